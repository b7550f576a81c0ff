#pragma once
// Procedural textures for the synthetic scenes: albedo as a pure function of surface coordinates
// (metres), the face size and a per-primitive seed. Every pattern carries high-frequency detail
// (grout, grain, speckle, print) so ORB finds features on walls and floors too.
#include "core/common/image.h"

#include <Eigen/Core>

#include <cstdint>

namespace rrg::synth {

enum class TextureKind : uint8_t {
  Solid,       // a, lightly mottled
  Checker,     // a / b squares of side `scale`
  Tiles,       // marble tiles a..b of side `scale`, grout c of width `param`
  Wood,        // planks of width `scale` along u, grain between a and b, seams c
  Plaster,     // a with fbm mottling and fine speckle
  Wallpaper,   // a with stripes b (period `scale`) and motifs c
  Fabric,      // weave of a and b with soft mottling
  Carpet,      // a / b geometric pattern with fibre noise
  Poster,      // framed picture: gradient a..b, blobs and stripes from the seed, frame c
  Screen,      // TV: dark glass with dim picture content
  Whiteboard,  // off-white a with marker strokes and a frame c
  Books,       // book spines of random widths and colours along u
  Leaves,      // foliage: a..b blotches
  Metal,       // brushed metal a
};

struct Texture {
  TextureKind kind = TextureKind::Solid;
  Color a{0.5f, 0.5f, 0.5f}, b{0.3f, 0.3f, 0.3f}, c{0.1f, 0.1f, 0.1f};  // linear RGB palette
  float scale = 0.3f;   // characteristic size in metres (tile side, plank width, stripe period)
  float param = 0.004f; // kind-specific (grout width, ...)
};

// Albedo (linear RGB in [0,1]) at face coordinates uv (metres from the face corner) on a face of
// size face_size (metres); seed varies the pattern between primitives.
Color eval_texture(const Texture& texture, const Eigen::Vector2f& uv, const Eigen::Vector2f& face_size,
                   uint32_t seed);

// 8-bit sRGB triple -> linear RGB (palette helper for presets).
Color srgb(int r, int g, int b);

// 2D value noise in [0,1] and its fractal sum (octaves of halving amplitude), exposed for tests.
float value_noise(float x, float y, uint32_t seed);
float fbm(float x, float y, uint32_t seed, int octaves);

}  // namespace rrg::synth
