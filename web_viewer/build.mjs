// Builds the viewer into dist/: one ES-module bundle (esbuild), index.html, style.css and the
// Draco decoder shipped inside the `three` package (no CDN: every asset is local).
import { build } from "esbuild";
import { cpSync, mkdirSync, rmSync, readdirSync, statSync } from "node:fs";
import { gzipSync } from "node:zlib";
import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const root = dirname(fileURLToPath(import.meta.url));
const dist = join(root, "dist");
rmSync(dist, { recursive: true, force: true });
mkdirSync(join(dist, "draco"), { recursive: true });

await build({
  // Spark (the splats, ~2.7 MB with its inlined wasm) is a separate chunk loaded on demand, so
  // the mesh is drawn while it loads.
  entryPoints: { viewer: join(root, "src/main.js") },
  bundle: true,
  splitting: true,
  format: "esm",
  minify: true,
  sourcemap: false,
  target: "es2022",
  outdir: dist,
  chunkNames: "chunks/[name]-[hash]",
  logLevel: "warning",
});
cpSync(join(root, "src/index.html"), join(dist, "index.html"));
cpSync(join(root, "src/style.css"), join(dist, "style.css"));
const draco = join(root, "node_modules/three/examples/jsm/libs/draco");
for (const f of ["draco_decoder.wasm", "draco_wasm_wrapper.js", "draco_decoder.js"])
  cpSync(join(draco, f), join(dist, "draco", f));

// Sizes (the report's figures): every file, and the JS bundle gzipped.
let total = 0;
const walk = (d) => readdirSync(d).forEach((f) => {
  const p = join(d, f);
  if (statSync(p).isDirectory()) walk(p);
  else total += statSync(p).size;
});
walk(dist);
const jsFiles = ["viewer.js", ...readdirSync(join(dist, "chunks")).map((f) => `chunks/${f}`)];
const sizes = jsFiles.map((f) => { const b = readFileSync(join(dist, f)); return [f, b.length, gzipSync(b).length]; });
const [js, gz] = sizes.reduce(([a, b], [, x, y]) => [a + x, b + y], [0, 0]);
console.log(`[viewer] dist ${total} bytes; JavaScript ${js} bytes, gzipped ${gz} bytes (` +
            sizes.map(([f, x, y]) => `${f} ${x} / ${y}`).join(", ") + ")");
