// End-to-end test of the browser viewer (issue #10, docs/viewer.md) in headless Debian Chromium
// (playwright-core, WebGL through SwiftShader; no browser is downloaded):
//   1. a small synthetic capture (240 frames at 2 fps) streams in real time into the real `rrg serve` (gRPC + HTTP);
//   2. the HTTP API answers with the documented errors (401 / 400 naming the parameter / 404) and
//      ETags (a chunk or the SPZ asked again with If-None-Match is 304);
//   3. the viewer draws mesh and splats: the screenshot is not uniform;
//   4. reflection-aware mode shows the server's render (differs from the scene view), and the
//      C / C_b / R·C_r toggles change the image (R·C_r differs from C);
//   5. pose events move the frustum.
// Usage: node viewer_e2e.mjs RRG_BINARY ARTIFACT_DIR. Screenshots and figures go to ARTIFACT_DIR.
import { spawn, execFileSync } from "node:child_process";
import { createRequire } from "node:module";
import { existsSync, mkdirSync, mkdtempSync, openSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
const { chromium } = createRequire(join(repo, "web_viewer/package.json"))("playwright-core");
const [rrg, artifacts] = [resolve(process.argv[2] ?? ""), resolve(process.argv[3] ?? "web-artifacts")];
const chromiumPath = process.env.RRG_CHROMIUM ?? "/usr/bin/chromium";
const ADMIN = "web-test-admin-key";
const started = Date.now();
const children = [];
const tmp = mkdtempSync(join(tmpdir(), "rrg-web-"));
mkdirSync(artifacts, { recursive: true });

const log = (...a) => console.log(`[web ${((Date.now() - started) / 1000).toFixed(1)}s]`, ...a);
function check(cond, what) {
  if (!cond) throw new Error(`check failed: ${what}`);
  log(`ok: ${what}`);
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function waitFor(f, what, timeoutMs = 60000) {
  const end = Date.now() + timeoutMs;
  for (;;) {
    const v = await f().catch(() => null);
    if (v) return v;
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(200);
  }
}
function start(args, name) {
  const logFd = openSync(join(artifacts, `${name}.log`), "w");
  const p = spawn(rrg, args, { stdio: ["ignore", logFd, logFd] });
  p.exited = new Promise((r) => p.on("exit", (code, signal) => r({ code, signal })));
  children.push(p);
  return p;
}

// Mean absolute difference of two RGBA arrays (0..255), over RGB.
function meanAbsDiff(a, b) {
  let s = 0, n = 0;
  for (let i = 0; i < a.length; i += 4) for (let c = 0; c < 3; c++, n++) s += Math.abs(a[i + c] - b[i + c]);
  return s / n;
}
function stddev(a) {
  let s = 0, s2 = 0, n = 0;
  for (let i = 0; i < a.length; i += 4) for (let c = 0; c < 3; c++, n++) { s += a[i + c]; s2 += a[i + c] ** 2; }
  return Math.sqrt(Math.max(0, s2 / n - (s / n) ** 2));
}

async function main() {
  // --- a capture streaming in real time: 2 fps, the camera moving 1 cm per frame -----------------
  // 2 cm voxels: a 160-pixel-wide image (fx = 128) spans ~2 cm per pixel at 2.5 m, so finer voxels
  // add triangles (and software-rendering time) without detail. RRG_WEB_VOXEL overrides it.
  const voxel = process.env.RRG_WEB_VOXEL ?? "0.02";
  const data = join(tmp, "data");
  execFileSync(rrg, ["synth", "--preset", "mirror_room", "--frames", "240", "--width", "160", "--height", "120", "--novel", "0",
                     "--fps", "2", "--speed", "0.02", "--out", data], { stdio: "inherit" });
  const server = start(["serve", "--address", "127.0.0.1:0", "--port-file", join(tmp, "grpc.port"), "--device", "cpu",
         "--http-port", "0", "--http-port-file", join(tmp, "http.port"), "--viewer-dir", join(repo, "web_viewer/dist"),
         "--admin-key", ADMIN], "serve");
  const readPort = (f) => existsSync(f) && Number(readFileSync(f, "utf8").trim());
  const grpcPort = await waitFor(async () => readPort(join(tmp, "grpc.port")), "the gRPC port");
  const httpPort = await waitFor(async () => readPort(join(tmp, "http.port")), "the HTTP port");
  const base = `http://127.0.0.1:${httpPort}`;
  log(`serve: gRPC ${grpcPort}, HTTP ${httpPort}`);
  const stream = start(["stream", "--dataset", data, "--server", `127.0.0.1:${grpcPort}`, "--session-id", "webtest",
                        "--realtime", "--window", "1", "--set", "sync=true", "--set", `tsdf.voxel_size=${voxel}`], "stream");

  // --- the API ----------------------------------------------------------------------------------
  const auth = { Authorization: `Bearer ${ADMIN}` };
  const api = (p, h = auth) => fetch(base + p, { headers: h });
  await waitFor(async () => (await api("/api/sessions/webtest")).ok, "the session");
  await waitFor(async () => (await (await api("/api/sessions/webtest/mesh/chunks")).json()).chunks.length > 0, "mesh chunks");
  check((await api("/api/sessions/webtest", {})).status === 401, "no token -> 401");
  check((await api("/api/sessions/webtest?token=wrong", {})).status === 401, "wrong token -> 401");
  check((await api("/api/sessions/nosuch")).status === 404, "unknown session -> 404");
  check((await api("/api/sessions", {})).status === 401, "session list without the admin key -> 401");
  const list = await (await api("/api/sessions")).json();
  check(list.sessions.some((s) => s.id === "webtest"), "session list names the session");
  const info = await (await api(`/api/sessions/webtest?token=${ADMIN}`, {})).json();
  check(info.units === "metres" && info.axes?.camera?.includes("OpenCV"), "info states units and axes");
  const bad = await api("/api/sessions/webtest/render?pose=1,2,3");
  check(bad.status === 400 && (await bad.json()).error.startsWith("pose"), "bad pose -> 400 naming 'pose'");
  const badPass = await api("/api/sessions/webtest/render?pose=0,0,0,0,0,0,1&pass=nope");
  check(badPass.status === 400 && (await badPass.json()).error.startsWith("pass"), "bad pass -> 400 naming 'pass'");
  const badW = await api("/api/sessions/webtest/render?pose=0,0,0,0,0,0,1&fx=100&fy=100&w=-3&h=10");
  check(badW.status === 400 && (await badW.json()).error.startsWith("w"), "bad width -> 400 naming 'w'");
  check((await api("/api/sessions/webtest/mesh/chunk/1_2.drc")).status === 400, "malformed chunk key -> 400");
  check((await api("/api/sessions/webtest/mesh/chunk/9999_0_0.drc")).status === 404, "chunk without blocks -> 404");
  const chunks = (await (await api("/api/sessions/webtest/mesh/chunks")).json()).chunks;
  const c0 = await api(`/api/sessions/webtest/mesh/chunk/${chunks[0].key}.drc`);
  const etag = c0.headers.get("etag");
  check([200, 204].includes(c0.status) && etag, "chunk download with an ETag");
  const again = await api(`/api/sessions/webtest/mesh/chunk/${chunks[0].key}.drc`, { ...auth, "If-None-Match": etag });
  // The chunk may have changed meanwhile (frames keep arriving): then the ETag differs.
  check(again.status === 304 || again.headers.get("etag") !== etag, "same ETag -> 304 Not Modified");
  const png = await api("/api/sessions/webtest/render?pose=0,0,0,0,0,0,1&pass=base");
  check(png.status === 200 && png.headers.get("content-type") === "image/png", "render -> PNG");
  const wasm = await fetch(`${base}/draco/draco_decoder.wasm`);
  check(wasm.headers.get("content-type") === "application/wasm", "wasm served as application/wasm");

  // --- the viewer in Chromium -------------------------------------------------------------------
  const browser = await chromium.launch({
    executablePath: chromiumPath,
    args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", "--no-sandbox"],
  });
  try {
    const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
    const pageErrors = [];
    page.on("pageerror", (e) => pageErrors.push(String(e)));
    page.on("console", (m) => { if (m.type() === "error") log(`console: ${m.text()}`); });
    await page.goto(`${base}/?session=webtest&token=${ADMIN}`);
    await page.waitForFunction(() => window.rrgViewer && window.rrgViewer.firstMeshMs !== null && window.rrgViewer.firstSplatsMs !== null,
                               null, { timeout: 120000, polling: 200 });
    const firstMeshMs = await page.evaluate(() => window.rrgViewer.firstMeshMs);
    const firstSplatsMs = await page.evaluate(() => window.rrgViewer.firstSplatsMs);
    const fullMeshMs = await page.waitForFunction(() => window.rrgViewer.fullMeshMs, null, { timeout: 120000 })
      .then((h) => h.jsonValue());
    const timeline = await page.evaluate(() => window.rrgViewer.timeline);
    log("timeline", JSON.stringify(timeline));
    log(`after page open: first mesh chunk drawn ${firstMeshMs.toFixed(0)} ms, the whole first mesh ` +
        `${fullMeshMs.toFixed(0)} ms, splats ${firstSplatsMs?.toFixed(0)} ms`);
    await sleep(500);
    // Pixels of what is on screen (the WebGL canvas, or the server's image over it), 160x120.
    const pixels = () => page.evaluate(async () => {
      const c = document.createElement("canvas");
      c.width = 160; c.height = 120;
      const g = c.getContext("2d");
      const img = document.getElementById("server-view");
      if (!img.hidden) { await img.decode().catch(() => {}); g.drawImage(img, 0, 0, 160, 120); }
      else g.drawImage(document.getElementById("canvas"), 0, 0, 160, 120);
      return Array.from(g.getImageData(0, 0, 160, 120).data);
    });
    const shot = (name) => page.screenshot({ path: join(artifacts, `viewer_${name}.png`) });

    const scene = await pixels();
    await shot("scene");
    const sceneStd = stddev(scene);
    check(sceneStd > 2, `scene view is not uniform (std ${sceneStd.toFixed(1)} of 255)`);

    const renders = () => page.evaluate(() => window.rrgViewer.serverRenders);
    const showPass = async (button, pass) => {
      const n = await renders();
      await page.click(button);
      await page.waitForFunction(([n, pass]) => window.rrgViewer.serverRenders > n && window.rrgViewer.serverViewPass === pass,
                                 [n, pass], { timeout: 60000 });
      await sleep(200);
      return pixels();
    };
    const final = await showPass("#mode", "final");
    await shot("final");
    check(stddev(final) > 2, "server render C is not uniform");
    const dScene = meanAbsDiff(scene, final);
    check(dScene > 1, `reflection-aware mode changes the image (mean |diff| ${dScene.toFixed(1)})`);
    const baseView = await showPass('#passes button[data-pass="base"]', "base");
    await shot("base");
    const refl = await showPass('#passes button[data-pass="reflection"]', "reflection");
    await shot("reflection");
    const dRefl = meanAbsDiff(final, refl);
    check(dRefl > 1, `R·C_r toggle changes the image (mean |diff| to C ${dRefl.toFixed(1)})`);
    const dBase = meanAbsDiff(final, baseView);
    log(`C vs C_b mean |diff| ${dBase.toFixed(2)} (non-zero where a reflective plane is accepted)`);
    await page.click("#mode");  // back to the scene

    // pose events move the frustum
    const p0 = await page.evaluate(() => ({ n: window.rrgViewer.poses, p: window.rrgViewer.frustum,
                                            fetches: window.rrgViewer.chunkFetches }));
    check(stream.exitCode === null, "the capture is still streaming");
    const moved = await page.waitForFunction(([n0, p]) => {
      const v = window.rrgViewer;
      const d = Math.hypot(v.frustum[0] - p[0], v.frustum[1] - p[1], v.frustum[2] - p[2]);
      return v.poses >= n0 + 2 && d > 1e-3 ? { poses: v.poses, d } : null;
    }, [p0.n, p0.p], { timeout: 60000 });
    const mv = await moved.jsonValue();
    check(true, `pose events moved the frustum ${(mv.d * 100).toFixed(1)} cm over ${mv.poses - p0.n} poses`);
    // map events: the chunks that changed are fetched again
    const fetched = await page.waitForFunction((f0) => window.rrgViewer.chunkFetches > f0 && window.rrgViewer.chunkFetches,
                                               p0.fetches, { timeout: 60000 }).then((h) => h.jsonValue());
    check(true, `map events refreshed the mesh (${fetched - p0.fetches} changed chunks fetched again)`);
    await shot("after_poses");
    const state = await page.evaluate(() => {
      const { meshChunks, meshTriangles, splats, poses, refreshes, chunkFetches, errors } = window.rrgViewer;
      return { meshChunks, meshTriangles, splats, poses, refreshes, chunkFetches, errors };
    });
    log("viewer state", JSON.stringify(state));
    check(pageErrors.length === 0 && state.errors.length === 0, `no page errors (${[...pageErrors, ...state.errors].join("; ")})`);
    const figures = { firstMeshMs, fullMeshMs, firstSplatsMs, timeline, sceneStd, dScene, dRefl, dBase, ...state,
                      runtimeS: (Date.now() - started) / 1000 };
    writeFileSync(join(artifacts, "figures.json"), JSON.stringify(figures, null, 2));
    log("figures", JSON.stringify(figures));
  } finally {
    await browser.close();
  }
  // SIGTERM: a graceful shutdown with the HTTP side on (exit code 0 within the grace period).
  stream.kill("SIGTERM");
  await stream.exited;
  server.kill("SIGTERM");
  const end = await Promise.race([server.exited, sleep(20000).then(() => null)]);
  check(end && end.code === 0, `rrg serve shut down cleanly on SIGTERM (${JSON.stringify(end)})`);
}

let code = 0;
try {
  await main();
  log(`PASS in ${((Date.now() - started) / 1000).toFixed(1)} s; screenshots in ${artifacts}`);
} catch (e) {
  console.error(e);
  code = 1;
} finally {
  for (const p of children.reverse()) if (p.exitCode === null && p.signalCode === null) p.kill("SIGTERM");
  await Promise.race([Promise.all(children.map((p) => p.exited)), sleep(10000)]);
  for (const p of children) if (p.exitCode === null && p.signalCode === null) p.kill("SIGKILL");
  rmSync(tmp, { recursive: true, force: true });
}
process.exit(code);
