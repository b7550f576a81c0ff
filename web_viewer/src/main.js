// RRG-SLAM browser viewer (issue #10, docs/viewer.md): mesh chunks + base splats in one three.js
// scene, live frustum and trajectory from server-sent pose events, incremental refresh on map
// events, and a reflection-aware mode that shows the server's render (C, C_b or R·C_r) for this
// camera. window.rrgViewer exposes the state the end-to-end test (tests/web) waits on.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { FlyControls } from "three/examples/jsm/controls/FlyControls.js";
import { Api, listSessions, poseMatrix } from "./api.js";
import { CameraPath, MeshChunks, Splats } from "./scene_parts.js";

const $ = (id) => document.getElementById(id);
const state = window.rrgViewer = {
  session: null, meshChunks: 0, meshTriangles: 0, splats: 0, poses: 0, frustum: null,
  firstMeshMs: null, fullMeshMs: null, firstSplatsMs: null, mode: "scene", pass: "final", serverRenders: 0,
  serverViewPass: null, mapVersion: 0, refreshes: 0, chunkFetches: 0, errors: [], timeline: [],
};
const mark = state.mark = (label) => { if (!state.timeline.some((t) => t[0] === label)) state.timeline.push([label, Math.round(performance.now())]); };
mark("script");

const canvas = $("canvas");
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x15171c);
const camera = new THREE.PerspectiveCamera(60, 1, 0.02, 200);
const orbit = new OrbitControls(camera, canvas);
const fly = new FlyControls(camera, canvas);
fly.movementSpeed = 1.0;
fly.rollSpeed = 0.5;
fly.dragToLook = true;
fly.enabled = false;
let navMode = "orbit";

let api = null, path = null, mesh = null, splats = null;
let cameraPlaced = false;

function resize() {
  const w = window.innerWidth, h = window.innerHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}
window.addEventListener("resize", resize);
resize();

// ---- session picker -------------------------------------------------------------------------
const params = new URLSearchParams(location.search);
$("token").value = params.get("token") ?? "";
async function fillList() {
  try {
    const list = await listSessions($("token").value);
    $("session-list").replaceChildren(...list.map((s) => {
      const o = document.createElement("option");
      o.value = s.id;
      o.textContent = `${s.name || s.id} (${s.frames} frames, ${s.base_gaussians} Gaussians)`;
      return o;
    }));
  } catch (e) { $("picker-error").textContent = e.message; }
}
$("picker").onsubmit = (e) => {  // a fresh page per session
  e.preventDefault();
  location.search = `?session=${encodeURIComponent($("session-list").value)}&token=${encodeURIComponent($("token").value)}`;
};
if (params.get("session")) open(params.get("session"), params.get("token") ?? "");
else fillList();
$("token").onchange = () => { if (!api) fillList(); };

async function open(id, token) {
  $("picker-error").textContent = "";
  api = new Api(id, token);
  let info;
  try { info = await api.json(""); } catch (e) { $("picker-error").textContent = e.message; return; }
  state.session = info;
  mark("info");
  history.replaceState(null, "", `?session=${encodeURIComponent(id)}&token=${encodeURIComponent(token)}`);
  path = new CameraPath(scene, info.intrinsics);
  mesh = new MeshChunks(scene, api);
  mesh.onChunk = () => {  // the first chunk is drawn in the frame before the next callback
    if (state.firstMeshMs === null) requestAnimationFrame(() => { state.firstMeshMs ??= performance.now(); });
  };
  splats = new Splats(scene, renderer, api);
  if (info.frames > 0) placeCamera(info.pose);
  const events = api.events();
  events.addEventListener("hello", (e) => { const d = JSON.parse(e.data); if (d.frames > 0) onPose(d.pose); });
  events.addEventListener("pose", (e) => onPose(JSON.parse(e.data).pose));
  events.addEventListener("map", (e) => { state.mapVersion = JSON.parse(e.data).map_version; scheduleRefresh(); });
  events.addEventListener("closed", () => { events.close(); $("picker-error").textContent = "session closed"; });
  scheduleRefresh(0);
}

function onPose(pose) {
  path.update(pose);
  state.poses++;
  state.frustum = pose.slice(0, 3);
  if (!cameraPlaced || $("follow").checked) placeCamera(pose);
}

// The browser camera at T_wc: three.js looks down -z with y up, OpenCV down +z with y down.
function placeCamera(pose) {
  const m = poseMatrix(THREE, pose).multiply(new THREE.Matrix4().makeScale(1, -1, -1));
  m.decompose(camera.position, camera.quaternion, new THREE.Vector3());
  if (!cameraPlaced) camera.up.set(0, -1, 0).applyQuaternion(poseMatrixQuat(pose)).normalize();
  const back = new THREE.Vector3(0, 0, 1).applyQuaternion(camera.quaternion);
  const forward = back.clone().negate();
  camera.position.addScaledVector(back, 0.8);  // a little behind, so its frustum is in view
  orbit.target.copy(camera.position).addScaledVector(forward, 2.0);
  camera.lookAt(orbit.target);
  orbit.update();
  cameraPlaced = true;
  cameraMoved();
}
const poseMatrixQuat = (p) => new THREE.Quaternion(p[3], p[4], p[5], p[6]).normalize();

// ---- incremental refresh on map events ------------------------------------------------------
let refreshTimer = null, refreshing = false, refreshAgain = false, lastSplats = 0;
function scheduleRefresh(delay = 400) {
  if (refreshing) { refreshAgain = true; return; }
  if (refreshTimer === null) refreshTimer = setTimeout(refresh, delay);
}
async function refresh() {
  refreshTimer = null;
  refreshing = true;
  try {
    await mesh.refresh();
    state.meshChunks = [...mesh.chunks.values()].filter((c) => c.mesh).length;
    state.meshTriangles = mesh.triangles;
    if (state.meshTriangles > 0 && state.fullMeshMs === null) requestAnimationFrame(() => {
      state.fullMeshMs ??= performance.now();  // every chunk of the first listing drawn
    });
    state.chunkFetches = mesh.fetched;
    refreshSplats();
    state.refreshes++;
    if (state.mode === "server") requestServerView();
  } catch (e) {
    state.errors.push(String(e));
    console.error(e);
  }
  refreshing = false;
  if (refreshAgain) { refreshAgain = false; scheduleRefresh(); }
}

// The splats refresh on their own (Spark loads in the background; the mesh never waits for it),
// at most every 1.5 s, with a trailing refresh so the last map change is not missed.
let splatsBusy = false, splatsTimer = null;
async function refreshSplats() {
  const wait = lastSplats + 1500 - performance.now();
  if (splatsBusy || wait > 0) {
    if (splatsTimer === null) splatsTimer = setTimeout(() => { splatsTimer = null; refreshSplats(); }, Math.max(wait, 200));
    return;
  }
  splatsBusy = true;
  lastSplats = performance.now();
  try {
    if (await splats.refresh()) {
      state.splats = splats.count;
      requestAnimationFrame(() => { state.firstSplatsMs ??= performance.now(); });
    }
  } catch (e) {
    state.errors.push(String(e));
    console.error(e);
  }
  splatsBusy = false;
}

// ---- reflection-aware mode: the server's three-pass render for this camera ------------------
const img = $("server-view");
let viewSeq = 0, viewTimer = null;
function cameraMoved() {
  if (state.mode !== "server") return;
  clearTimeout(viewTimer);
  viewTimer = setTimeout(requestServerView, 120);
}
async function requestServerView() {
  if (!api) return;
  const seq = ++viewSeq;
  camera.updateMatrixWorld();
  // OpenCV T_wc of the browser camera; a render of at most 480 px width, same field of view.
  const m = camera.matrixWorld.clone().multiply(new THREE.Matrix4().makeScale(1, -1, -1));
  const t = new THREE.Vector3(), q = new THREE.Quaternion();
  m.decompose(t, q, new THREE.Vector3());
  const w = Math.min(480, canvas.clientWidth), h = Math.max(1, Math.round(w / camera.aspect));
  const f = h / 2 / Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2);
  const pass = state.pass;
  const url = api.renderUrl({
    pose: [t.x, t.y, t.z, q.x, q.y, q.z, q.w].map((v) => v.toFixed(6)).join(","),
    fx: f.toFixed(3), fy: f.toFixed(3), cx: (w / 2).toFixed(3), cy: (h / 2).toFixed(3), w, h, pass,
  });
  const r = await fetch(url, { cache: "no-store" });
  if (!r.ok) { state.errors.push(`render: ${r.status}`); return; }
  const blob = await r.blob();
  if (seq !== viewSeq) return;  // a newer view was asked for meanwhile
  const old = img.src;
  img.src = URL.createObjectURL(blob);
  await img.decode().catch(() => {});
  if (old) URL.revokeObjectURL(old);
  state.serverRenders++;
  state.serverViewPass = pass;
}
function setMode(mode) {
  state.mode = mode;
  img.hidden = mode !== "server";
  $("passes").hidden = mode !== "server";
  $("mode").textContent = `reflection-aware: ${mode === "server" ? "on" : "off"}`;
  $("mode").classList.toggle("on", mode === "server");
  if (mode === "server") requestServerView();
}
function setPass(pass) {
  state.pass = pass;
  for (const b of document.querySelectorAll("#passes button")) b.classList.toggle("on", b.dataset.pass === pass);
  if (state.mode === "server") requestServerView();
}
$("mode").onclick = () => setMode(state.mode === "server" ? "scene" : "server");
for (const b of document.querySelectorAll("#passes button")) b.onclick = () => setPass(b.dataset.pass);
function setNav(mode) {
  navMode = mode;
  orbit.enabled = mode === "orbit";
  fly.enabled = mode === "fly";
  if (mode === "orbit") orbit.target.copy(camera.position).add(new THREE.Vector3(0, 0, -2).applyQuaternion(camera.quaternion));
  $("nav").textContent = mode;
}
$("nav").onclick = () => setNav(navMode === "orbit" ? "fly" : "orbit");
$("show-mesh").onchange = (e) => { if (mesh) mesh.group.visible = e.target.checked; };
$("show-splats").onchange = (e) => splats?.setVisible(e.target.checked);
window.addEventListener("keydown", (e) => {
  if (e.target instanceof HTMLInputElement) return;
  if (e.key === "m" || e.key === "M") $("mode").click();
  else if (e.key === "f" || e.key === "F") $("nav").click();
  else if (e.key === "1") setPass("final");
  else if (e.key === "2") setPass("base");
  else if (e.key === "3") setPass("reflection");
});
orbit.addEventListener("change", cameraMoved);
Object.assign(state, { setMode, setPass, setNav });

// ---- render loop and stats ------------------------------------------------------------------
let frames = 0, fps = 0, fpsStart = performance.now(), lastTick = performance.now(), lastFly = new THREE.Matrix4();
renderer.setAnimationLoop(() => {
  const dt = (performance.now() - lastTick) / 1000;
  lastTick = performance.now();
  if (navMode === "fly") {
    fly.update(dt);
    if (!lastFly.equals(camera.matrix)) { lastFly.copy(camera.matrix); cameraMoved(); }
  }
  renderer.render(scene, camera);
  frames++;
  const now = performance.now();
  if (now - fpsStart >= 1000) {
    fps = frames * 1000 / (now - fpsStart);
    frames = 0;
    fpsStart = now;
    state.fps = fps;
    $("stats").textContent = [
      `FPS        ${fps.toFixed(1)}`,
      `Gaussians  ${state.splats}`,
      `mesh       ${state.meshChunks} chunks, ${state.meshTriangles} triangles`,
      `map size   ${((mesh?.bytes ?? 0) / 1024).toFixed(0)} KiB mesh + ${((splats?.bytes ?? 0) / 1024).toFixed(0)} KiB splats`,
      `map        version ${state.mapVersion}, ${state.poses} poses`,
      state.session ? `session    ${state.session.id}` : "no session",
    ].join("\n");
  }
});
