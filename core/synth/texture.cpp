#include "core/synth/texture.h"

#include "core/synth/hash.h"

#include <algorithm>
#include <cmath>

namespace rrg::synth {
namespace {

using Eigen::Vector2f;

constexpr float kTwoPi = 6.28318531f;

float smooth(float t) { return t * t * (3.0f - 2.0f * t); }
float fract(float x) { return x - std::floor(x); }
float clamp01(float x) { return std::clamp(x, 0.0f, 1.0f); }
Color mix(const Color& a, const Color& b, float t) { return a + (b - a) * t; }
// Smooth 0..1 step of width w around edge e.
float soft_step(float e, float w, float x) { return clamp01((x - e) / w + 0.5f); }
Color hashed_color(uint32_t h) {
  // Saturated but not neon: a random hue at medium lightness.
  const float r = unit_float(hash_u32(h)), g = unit_float(hash_u32(h + 1)), b = unit_float(hash_u32(h + 2));
  return Color(0.05f + 0.75f * r * r, 0.05f + 0.75f * g * g, 0.05f + 0.75f * b * b);
}
// Speckle: per-cell random value on a fine grid (millimetre-scale print grain).
float speckle(const Vector2f& uv, float cell, uint32_t seed) {
  return unit_float(hash_lattice(int32_t(std::floor(uv.x() / cell)), int32_t(std::floor(uv.y() / cell)), seed));
}

Color solid(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float n = fbm(uv.x() * 6.0f, uv.y() * 6.0f, seed, 3);
  return t.a * (0.85f + 0.3f * n) * (0.94f + 0.12f * speckle(uv, 0.01f, seed));
}

Color checker(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const int i = int(std::floor(uv.x() / t.scale)), j = int(std::floor(uv.y() / t.scale));
  const Color base = ((i + j) & 1) ? t.a : t.b;
  return base * (0.88f + 0.24f * fbm(uv.x() * 9.0f, uv.y() * 9.0f, seed, 2));
}

Color tiles(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float s = t.scale;
  const float fu = uv.x() / s, fv = uv.y() / s;
  const int i = int(std::floor(fu)), j = int(std::floor(fv));
  const float lu = (fu - float(i)) * s, lv = (fv - float(j)) * s;  // metres inside the tile
  const float g = t.param * 0.5f;
  const float edge = std::min(std::min(lu, s - lu), std::min(lv, s - lv));
  const uint32_t h = hash3(uint32_t(i), uint32_t(j), seed);
  Color tile = mix(t.a, t.b, unit_float(h));
  // Marble veins: a distorted sine band, different orientation per tile.
  const float ang = unit_float(hash_u32(h)) * 3.14159f;
  const float w = uv.x() * std::cos(ang) + uv.y() * std::sin(ang);
  const float turb = fbm(uv.x() * 7.0f, uv.y() * 7.0f, seed + 11, 3);
  const float sv = std::sin((w * 9.0f + turb * 5.0f) * 3.14159f), s2 = sv * sv, s4 = s2 * s2;
  const float vein = s4 * s4;  // |sin|^8
  tile = tile * (0.92f + 0.14f * turb) * (1.0f - 0.35f * vein);
  return mix(t.c, tile, soft_step(g, 0.0015f, edge));
}

Color wood(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float s = t.scale;  // plank width across v
  const int plank = int(std::floor(uv.y() / s));
  const uint32_t h = hash_combine(uint32_t(plank), seed);
  const float plank_len = 1.2f;
  const float shifted_u = uv.x() + unit_float(h) * plank_len;
  const int seg = int(std::floor(shifted_u / plank_len));
  const uint32_t hs = hash_combine(h, uint32_t(seg));
  const float lv = uv.y() - float(plank) * s, lu = shifted_u - float(seg) * plank_len;
  const float n = fbm(uv.x() * 1.5f, uv.y() * 18.0f, hs, 3);
  const float rings = fract((lv * 14.0f + n * 2.5f + unit_float(hs) * 3.0f) * 2.0f);
  const float grain = 0.5f + 0.5f * std::sin(rings * kTwoPi);
  Color c = mix(t.a, t.b, grain * 0.8f + 0.2f * unit_float(hs >> 3));
  c *= 0.9f + 0.2f * speckle(Vector2f(uv.x() * 0.25f, uv.y()), 0.003f, hs);
  const float seam = std::min(std::min(lv, s - lv), std::min(lu, plank_len - lu));
  return mix(t.c, c, soft_step(0.002f, 0.002f, seam));
}

Color plaster(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float n = fbm(uv.x() * 3.0f, uv.y() * 3.0f, seed, 4);
  const float fine = fbm(uv.x() * 60.0f, uv.y() * 60.0f, seed + 7, 2);
  return t.a * (0.8f + 0.3f * n) * (0.9f + 0.2f * fine) * (0.95f + 0.1f * speckle(uv, 0.004f, seed));
}

Color wallpaper(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float p = t.scale;
  const float su = fract(uv.x() / p);
  Color c = su < 0.18f ? t.b : t.a;
  // Diamond lattice of small motifs, offset every other row.
  const float mu = uv.x() / (p * 0.5f), mv = uv.y() / (p * 0.5f);
  const int row = int(std::floor(mv));
  const float ou = fract(mu + (row & 1) * 0.5f) - 0.5f, ov = fract(mv) - 0.5f;
  const float d = std::abs(ou) + std::abs(ov);
  c = mix(c, t.c, 1.0f - soft_step(0.22f, 0.04f, d));
  const float ring = std::abs(d - 0.32f);
  c = mix(c, t.b, 0.6f * (1.0f - soft_step(0.02f, 0.02f, ring)));
  const float n = fbm(uv.x() * 4.0f, uv.y() * 4.0f, seed, 3);
  return c * (0.85f + 0.25f * n) * (0.95f + 0.1f * speckle(uv, 0.003f, seed));
}

Color fabric(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float weave = 0.5f + 0.25f * (std::sin(uv.x() * 900.0f) + std::sin(uv.y() * 900.0f));
  const float mottle = fbm(uv.x() * 5.0f, uv.y() * 5.0f, seed, 3);
  const float check = fbm(uv.x() * 25.0f, uv.y() * 25.0f, seed + 3, 2);
  Color c = mix(t.a, t.b, clamp01(0.6f * mottle + 0.4f * check));
  return c * (0.85f + 0.15f * weave) * (0.93f + 0.14f * speckle(uv, 0.004f, seed));
}

Color carpet(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float s = t.scale;
  const float fu = fract(uv.x() / s) - 0.5f, fv = fract(uv.y() / s) - 0.5f;
  const float d = std::max(std::abs(fu), std::abs(fv));
  const float motif = (std::abs(d - 0.3f) < 0.05f || std::abs(fu + fv) < 0.04f) ? 1.0f : 0.0f;
  Color c = mix(t.a, t.b, motif);
  const float fibre = speckle(uv, 0.002f, seed);
  return c * (0.8f + 0.3f * fibre) * (0.9f + 0.2f * fbm(uv.x() * 3.0f, uv.y() * 3.0f, seed, 2));
}

Color poster(const Texture& t, const Vector2f& uv, const Vector2f& size, uint32_t seed,
             float brightness) {
  const float x = uv.x() / size.x(), y = uv.y() / size.y();  // [0,1] over the face
  const float frame = 0.045f * std::min(size.x(), size.y()) / std::max(size.x(), size.y()) + 0.02f;
  if (x < frame || x > 1.0f - frame || y < frame || y > 1.0f - frame) {
    return t.c * (0.9f + 0.2f * speckle(uv, 0.004f, seed));
  }
  Color c = mix(t.a, t.b, y);
  // Stripes band across the picture.
  const float band_y = 0.2f + 0.6f * unit_float(hash_u32(seed + 5));
  if (std::abs(y - band_y) < 0.08f) {
    const float stripe = std::sin((x * 14.0f + y * 6.0f) * kTwoPi * 0.5f);
    c = mix(c, hashed_color(seed + 9), stripe > 0.0f ? 0.8f : 0.1f);
  }
  // Soft coloured blobs with hard rims.
  for (uint32_t k = 0; k < 6; ++k) {
    const uint32_t h = hash3(seed, k, 77);
    const float bx = 0.1f + 0.8f * unit_float(h), by = 0.1f + 0.8f * unit_float(hash_u32(h));
    const float r = 0.06f + 0.14f * unit_float(hash_u32(h + 3));
    const float dx = (x - bx) * size.x(), dy = (y - by) * size.y();
    const float d = std::sqrt(dx * dx + dy * dy) / (r * std::min(size.x(), size.y()));
    if (d < 1.0f) c = mix(c, hashed_color(h + 17), d < 0.92f ? 0.85f : 0.3f);
  }
  c *= 0.9f + 0.2f * fbm(uv.x() * 20.0f, uv.y() * 20.0f, seed, 2);
  return c * brightness;
}

Color whiteboard(const Texture& t, const Vector2f& uv, const Vector2f& size, uint32_t seed) {
  const float border = 0.025f;
  if (uv.x() < border || uv.y() < border || uv.x() > size.x() - border || uv.y() > size.y() - border)
    return t.c;
  Color c = t.a * (0.95f + 0.05f * fbm(uv.x() * 10.0f, uv.y() * 10.0f, seed, 2));
  // Marker strokes: wavy lines of text-like bumps.
  for (uint32_t k = 0; k < 7; ++k) {
    const uint32_t h = hash3(seed, k, 31);
    const float line_y = size.y() * (0.15f + 0.1f * float(k));
    const float x0 = size.x() * (0.05f + 0.3f * unit_float(h)), x1 = x0 + size.x() * (0.2f + 0.4f * unit_float(h + 1));
    if (uv.x() < x0 || uv.x() > std::min(x1, size.x() - 0.05f)) continue;
    const float wave = line_y + 0.02f * std::sin(uv.x() * 90.0f + float(k)) * std::sin(uv.x() * 13.0f);
    if (std::abs(uv.y() - wave) < 0.004f) c = hashed_color(h + 4) * 0.4f;
  }
  return c;
}

Color books(const Texture& t, const Vector2f& uv, uint32_t seed) {
  // Walk spines of random width 2..6 cm along u (a few steps at most per lookup: hashed cells).
  const float cell = 0.04f;
  const int i = int(std::floor(uv.x() / cell));
  const uint32_t h = hash_combine(uint32_t(i), seed);
  const float lu = uv.x() - float(i) * cell;
  const float split = cell * (0.3f + 0.4f * unit_float(h));
  const uint32_t hb = lu < split ? h : hash_u32(h);
  Color c = hashed_color(hb) * 0.8f;
  const float title = uv.y() - (0.3f + 0.2f * unit_float(hb + 2)) * 0.25f;
  if (std::abs(title) < 0.012f && std::abs(lu - (lu < split ? split * 0.5f : (split + cell) * 0.5f)) < 0.006f)
    c = t.a;
  const float gap = std::min(std::abs(lu), std::abs(lu - split));
  return mix(t.c, c, soft_step(0.001f, 0.001f, gap)) * (0.9f + 0.2f * speckle(uv, 0.003f, hb));
}

Color leaves(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float n = fbm(uv.x() * 30.0f, uv.y() * 30.0f, seed, 3);
  return mix(t.a, t.b, n) * (0.8f + 0.4f * speckle(uv, 0.008f, seed));
}

Color metal(const Texture& t, const Vector2f& uv, uint32_t seed) {
  const float brushed = speckle(Vector2f(uv.x() * 0.02f, uv.y()), 0.0005f, seed);
  return t.a * (0.85f + 0.15f * brushed) * (0.9f + 0.2f * fbm(uv.x() * 8.0f, uv.y() * 8.0f, seed, 2));
}

}  // namespace

float value_noise(float x, float y, uint32_t seed) {
  const float fx = std::floor(x), fy = std::floor(y);
  const int32_t ix = int32_t(fx), iy = int32_t(fy);
  const float tx = smooth(x - fx), ty = smooth(y - fy);
  const float v00 = unit_float(hash_lattice(ix, iy, seed));
  const float v10 = unit_float(hash_lattice(ix + 1, iy, seed));
  const float v01 = unit_float(hash_lattice(ix, iy + 1, seed));
  const float v11 = unit_float(hash_lattice(ix + 1, iy + 1, seed));
  const float a = v00 + (v10 - v00) * tx, b = v01 + (v11 - v01) * tx;
  return a + (b - a) * ty;
}

float fbm(float x, float y, uint32_t seed, int octaves) {
  float sum = 0.0f, amp = 0.5f, norm = 0.0f;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * value_noise(x, y, seed + uint32_t(o) * 101u);
    norm += amp;
    x = x * 2.03f + 17.1f;
    y = y * 2.03f - 5.3f;
    amp *= 0.5f;
  }
  return sum / norm;
}

Color srgb(int r, int g, int b) {
  auto lin = [](int v) { return std::pow(float(v) / 255.0f, 2.2f); };
  return {lin(r), lin(g), lin(b)};
}

Color eval_texture(const Texture& t, const Vector2f& uv, const Vector2f& size, uint32_t seed) {
  Color c = Color::Zero();
  switch (t.kind) {
    case TextureKind::Solid: c = solid(t, uv, seed); break;
    case TextureKind::Checker: c = checker(t, uv, seed); break;
    case TextureKind::Tiles: c = tiles(t, uv, seed); break;
    case TextureKind::Wood: c = wood(t, uv, seed); break;
    case TextureKind::Plaster: c = plaster(t, uv, seed); break;
    case TextureKind::Wallpaper: c = wallpaper(t, uv, seed); break;
    case TextureKind::Fabric: c = fabric(t, uv, seed); break;
    case TextureKind::Carpet: c = carpet(t, uv, seed); break;
    case TextureKind::Poster: c = poster(t, uv, size, seed, 1.0f); break;
    case TextureKind::Screen: c = poster(t, uv, size, seed, 0.25f); break;
    case TextureKind::Whiteboard: c = whiteboard(t, uv, size, seed); break;
    case TextureKind::Books: c = books(t, uv, seed); break;
    case TextureKind::Leaves: c = leaves(t, uv, seed); break;
    case TextureKind::Metal: c = metal(t, uv, seed); break;
  }
  return c.cwiseMax(0.0f).cwiseMin(1.0f);
}

}  // namespace rrg::synth
