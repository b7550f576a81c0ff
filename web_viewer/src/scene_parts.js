// Scene pieces: the live camera frustum and trajectory, the chunked Draco mesh, the base splats.
import * as THREE from "three";
import { DRACOLoader } from "three/examples/jsm/loaders/DRACOLoader.js";
// Spark loads on demand (a chunk of its own): the mesh does not wait for it.
let sparkModule = null;
const spark = () => (sparkModule ??= import("@sparkjsdev/spark"));
import { poseMatrix } from "./api.js";

// The camera of the latest pose event (a wire frustum in OpenCV camera axes) and the path so far.
export class CameraPath {
  constructor(scene, K, depth = 0.25) {
    const c = (u, v) => new THREE.Vector3((u - K.cx) / K.fx * depth, (v - K.cy) / K.fy * depth, depth);
    const o = new THREE.Vector3();
    const [a, b, d, e] = [c(0, 0), c(K.width, 0), c(K.width, K.height), c(0, K.height)];
    const up = c(K.width / 2, -K.height * 0.25);
    const pts = [o, a, o, b, o, d, o, e, a, b, b, d, d, e, e, a, a, up, up, b];
    this.frustum = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(pts),
      new THREE.LineBasicMaterial({ color: 0xffcc33 }));
    this.frustum.matrixAutoUpdate = false;
    this.frustum.visible = false;
    this.max = 1 << 16;
    this.positions = new Float32Array(this.max * 3);
    this.count = 0;
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(this.positions, 3));
    g.setDrawRange(0, 0);
    this.line = new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0x33ddff }));
    this.line.frustumCulled = false;
    scene.add(this.frustum, this.line);
    this.pose = null;
  }
  update(pose) {
    this.pose = pose;
    const m = poseMatrix(THREE, pose);
    this.frustum.matrix.copy(m);
    this.frustum.matrixWorldNeedsUpdate = true;
    this.frustum.visible = true;
    if (this.count < this.max) {
      this.positions.set(pose.slice(0, 3), this.count * 3);
      this.count++;
      const g = this.line.geometry;
      g.attributes.position.needsUpdate = true;
      g.setDrawRange(0, this.count);
    }
  }
}

// The Draco decoder (wasm, from the `three` package) starts loading with the page, in at most as
// many workers as the machine has cores.
const dracoLoader = new DRACOLoader().setDecoderPath("draco/").setDecoderConfig({ type: "wasm" })
  .setWorkerLimit(Math.max(1, Math.min(4, navigator.hardwareConcurrency || 2)));
dracoLoader.preload();

// The mesh as fixed spatial chunks: only chunks whose ETag changed are fetched again.
export class MeshChunks {
  constructor(scene, api) {
    this.api = api;
    this.group = new THREE.Group();
    scene.add(this.group);
    this.chunks = new Map();  // key -> {etag, mesh}
    this.loader = dracoLoader;
    this.material = new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.DoubleSide });
    this.triangles = 0;
    this.bytes = 0;
    this.fetched = 0;
    this.notModified = 0;
  }
  decode(bytes) {
    return new Promise((resolve, reject) => this.loader.parse(bytes, resolve, reject));
  }
  async refresh() {
    const list = await this.api.json("/mesh/chunks");
    window.rrgViewer?.mark("chunks listed");
    const live = new Set(list.chunks.map((c) => c.key));
    for (const [key, c] of this.chunks) if (!live.has(key)) this.drop(key, c);
    await Promise.all(list.chunks.map(async (info) => {
      const held = this.chunks.get(info.key);
      if (held && held.etag === info.etag) return;
      const r = await this.api.binary(`/mesh/chunk/${info.key}.drc`, held?.etag);
      if (r.status === 304) { this.notModified++; return; }
      if (held) this.drop(info.key, held);
      if (r.status === 204) { this.chunks.set(info.key, { etag: r.etag, mesh: null, bytes: 0 }); return; }
      window.rrgViewer?.mark("chunk fetched");
      const bytes = r.bytes.byteLength;  // read first: the decoder transfers the buffer to its worker
      const geometry = await this.decode(r.bytes);
      window.rrgViewer?.mark("chunk decoded");
      normaliseColours(geometry);
      const mesh = new THREE.Mesh(geometry, this.material);
      this.group.add(mesh);
      this.chunks.set(info.key, { etag: r.etag, mesh, bytes });
      this.fetched++;
      this.triangles += triangleCount(geometry);
      this.bytes += bytes;
      this.onChunk?.();
    }));
    return list.map_version;
  }
  drop(key, c) {
    if (c.mesh) {
      this.group.remove(c.mesh);
      this.triangles -= triangleCount(c.mesh.geometry);
      c.mesh.geometry.dispose();
    }
    this.bytes -= c.bytes ?? 0;
    this.chunks.delete(key);
  }
}

function triangleCount(g) { return g.index ? g.index.count / 3 : g.attributes.position.count / 3; }

// Draco colours arrive as 0..255 floats or normalised: make them 0..1.
function normaliseColours(g) {
  const c = g.attributes.color;
  if (!c || c.normalized) return;
  let max = 0;
  for (let i = 0; i < c.array.length; i++) max = Math.max(max, c.array[i]);
  if (max > 1.5) for (let i = 0; i < c.array.length; i++) c.array[i] /= 255;
  c.needsUpdate = true;
}

// The base Gaussians (SPZ) through Spark; refetched only when the server's ETag changes.
export class Splats {
  constructor(scene, renderer, api) {
    this.scene = scene;
    this.renderer = renderer;
    spark();  // start loading now
    this.api = api;
    this.etag = null;
    this.mesh = null;
    this.count = 0;
    this.bytes = 0;
    this.visible = true;
  }
  async refresh() {
    const r = await this.api.binary("/gaussians.spz", this.etag);
    if (r.status === 304) return false;
    this.etag = r.etag;
    if (r.status === 204) return false;
    const { SparkRenderer, SplatMesh, SplatFileType } = await spark();
    if (!this.sparkRenderer) this.scene.add(this.sparkRenderer = new SparkRenderer({ renderer: this.renderer }));
    const mesh = new SplatMesh({ fileBytes: new Uint8Array(r.bytes), fileType: SplatFileType.SPZ });
    await mesh.initialized;
    mesh.visible = this.visible;
    if (this.mesh) { this.scene.remove(this.mesh); this.mesh.dispose(); }
    this.mesh = mesh;
    this.scene.add(mesh);
    this.count = mesh.splats?.numSplats ?? mesh.packedSplats?.numSplats ?? mesh.extSplats?.numSplats ?? 0;
    if (!this.count) this.count = Number(r.gaussians ?? 0);
    this.bytes = r.bytes.byteLength;
    return true;
  }
  setVisible(v) { this.visible = v; if (this.mesh) this.mesh.visible = v; }
}
