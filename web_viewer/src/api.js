// The server's HTTP API (docs/viewer.md): JSON calls, binary downloads with ETags, events.
export class Api {
  constructor(sessionId, token) {
    this.id = sessionId;
    this.token = token;
  }
  headers(extra = {}) {
    return this.token ? { Authorization: `Bearer ${this.token}`, ...extra } : extra;
  }
  url(path) { return `/api/sessions/${encodeURIComponent(this.id)}${path}`; }
  async json(path) {
    const r = await fetch(this.url(path), { headers: this.headers() });
    if (!r.ok) throw new Error(`${path}: ${r.status} ${(await r.json().catch(() => ({}))).error ?? ""}`);
    return r.json();
  }
  // {status: 200 | 204 | 304, etag, bytes?: ArrayBuffer}
  async binary(path, etag) {
    const r = await fetch(this.url(path), { headers: this.headers(etag ? { "If-None-Match": etag } : {}), cache: "no-store" });
    if (r.status === 304 || r.status === 204) return { status: r.status, etag: r.headers.get("ETag") };
    if (!r.ok) throw new Error(`${path}: ${r.status}`);
    return { status: 200, etag: r.headers.get("ETag"), gaussians: r.headers.get("X-Gaussians"), bytes: await r.arrayBuffer() };
  }
  events() {
    // EventSource cannot set headers: the token goes in the query.
    return new EventSource(this.url(`/events?token=${encodeURIComponent(this.token)}`));
  }
  renderUrl(params) {
    const q = new URLSearchParams({ ...params, token: this.token });
    return this.url(`/render?${q}`);
  }
}

export async function listSessions(token) {
  const r = await fetch("/api/sessions", { headers: token ? { Authorization: `Bearer ${token}` } : {} });
  if (!r.ok) throw new Error(`session list: ${r.status} ${(await r.json().catch(() => ({}))).error ?? ""}`);
  return (await r.json()).sessions;
}

// [tx,ty,tz,qx,qy,qz,qw] (T_wc, OpenCV camera axes) <-> THREE.Matrix4.
export function poseMatrix(THREE, p) {
  return new THREE.Matrix4().compose(
    new THREE.Vector3(p[0], p[1], p[2]),
    new THREE.Quaternion(p[3], p[4], p[5], p[6]).normalize(),
    new THREE.Vector3(1, 1, 1));
}
