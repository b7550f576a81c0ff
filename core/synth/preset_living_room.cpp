// living_room: glossy marble tiles, a glossy TV screen and coffee table, sofa, bookshelf, lamp,
// sideboard, plant, rug and posters in a 5 x 4 x 2.7 m room. The TV wall is y = 4.
#include "core/synth/presets.h"
#include "core/synth/scene_builder.h"

namespace rrg::synth {

using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;

SceneSpec make_living_room(uint32_t seed) {
  SceneBuilder b("living_room", preset_list()[0].description, seed);
  // Materials: F0 > 0 only on the floor, the TV screen and the coffee table top.
  const auto floor = b.material("marble_tiles", tex(TextureKind::Tiles, srgb(168, 160, 148), srgb(120, 112, 104),
                                                    srgb(70, 66, 62), 0.5f, 0.005f), 0.25f, 0.03f);
  const Color Z = Color::Zero();
  const auto walls = b.material("wallpaper", tex(TextureKind::Wallpaper, srgb(214, 200, 178), srgb(188, 168, 140),
                                                 srgb(150, 120, 96), 0.32f));
  const auto ceiling = b.material("plaster", tex(TextureKind::Plaster, srgb(236, 234, 228), Z, Z, 1.0f));
  const auto oak = b.material("oak", tex(TextureKind::Wood, srgb(170, 120, 78), srgb(120, 78, 46), srgb(60, 40, 25), 0.2f));
  const auto walnut_gloss = b.material("lacquered_walnut", tex(TextureKind::Wood, srgb(120, 76, 48), srgb(80, 48, 30),
                                                               srgb(40, 26, 18), 0.3f), 0.2f, 0.02f);
  const auto fabric = b.material("sofa_fabric", tex(TextureKind::Fabric, srgb(70, 96, 120), srgb(52, 74, 96), Z, 0.1f));
  const auto cushion = b.material("cushion", tex(TextureKind::Fabric, srgb(200, 140, 60), srgb(170, 100, 40), Z, 0.1f));
  const auto books = b.material("books", tex(TextureKind::Books, srgb(230, 220, 190), Z, srgb(30, 25, 20), 0.04f));
  const auto metal = b.material("steel", tex(TextureKind::Metal, srgb(150, 150, 155), Z, Z, 0.1f));
  const auto black = b.material("black_plastic", tex(TextureKind::Solid, srgb(30, 30, 32), Z, Z, 0.1f));
  const auto screen = b.material("tv_screen", tex(TextureKind::Screen, srgb(40, 90, 160), srgb(200, 120, 60),
                                                  srgb(8, 8, 10), 1.0f), 0.12f, 0.0f);
  const auto rug = b.material("rug", tex(TextureKind::Carpet, srgb(150, 40, 40), srgb(220, 190, 140), Z, 0.25f));
  const HomeMaterials home = home_materials(b);
  const auto shade = home.lamp_shade, panel = home.light_panel, pot = home.terracotta, leaves = home.leaves,
             door = home.door;
  auto poster = [&](const std::string& n, Color a, Color c2) {
    return b.material(n, tex(TextureKind::Poster, a, c2, srgb(20, 20, 20), 1.0f));
  };

  b.room({5.0f, 4.0f, 2.7f}, floor, walls, ceiling);
  // TV wall (y = 4): cabinet, TV body, glossy screen, small poster.
  b.box_between("tv_cabinet", {1.55f, 3.55f, 0.0f}, {3.45f, 4.0f, 0.5f}, oak, Category::Cabinet);
  b.box_between("tv_body", {1.72f, 3.88f, 0.72f}, {3.28f, 3.97f, 1.62f}, black, Category::Tv);
  b.rect("tv_screen", {2.5f, 3.875f, 1.17f}, {0, -1, 0}, {0, 0, 1}, 1.46f, 0.82f, screen, Category::Tv);
  b.rect("poster_tv_left", {0.8f, 3.995f, 1.55f}, {0, -1, 0}, {0, 0, 1}, 0.6f, 0.85f,
         poster("poster_a", srgb(230, 200, 120), srgb(60, 90, 140)), Category::Poster);
  b.sphere("vase_ball", {1.85f, 3.78f, 0.62f}, 0.12f, pot, Category::Sculpture);
  // Sofa wall (y = 0).
  b.sofa("sofa", {1.3f, 0.05f}, {3.7f, 0.95f}, {0, 1}, fabric, cushion, Category::Sofa);
  b.rect("poster_sofa", {2.5f, 0.005f, 1.6f}, {0, 1, 0}, {0, 0, 1}, 1.5f, 0.65f,
         poster("poster_b", srgb(240, 230, 210), srgb(160, 60, 50)), Category::Poster);
  // Coffee table on a rug.
  b.rect("rug", {2.5f, 1.85f, 0.004f}, {0, 0, 1}, {0, 1, 0}, 2.1f, 1.3f, rug, Category::Rug);
  b.table("coffee_table", {2.5f, 1.85f}, {1.2f, 0.62f, 0.05f}, 0.45f, walnut_gloss, metal, Category::Table);
  b.box("table_books", {2.2f, 1.8f, 0.48f}, {0.3f, 0.22f, 0.06f}, books, Category::Books, 12.0f);
  b.cylinder("table_mug", {2.85f, 1.95f, 0.45f}, 0.045f, 0.1f, cushion, Category::Sculpture);
  // Bookshelf on the x = 0 wall, door next to it.
  b.bookshelf("bookshelf", {0.0f, 1.5f, 0.0f}, {0.36f, 2.7f, 2.0f}, 3, {1, 0, 0}, oak, books);
  b.rect("door", {0.005f, 0.7f, 1.025f}, {1, 0, 0}, {0, 0, 1}, 0.9f, 2.05f, door, Category::Door);
  b.rect("poster_left", {0.005f, 3.3f, 1.5f}, {1, 0, 0}, {0, 0, 1}, 0.7f, 0.9f,
         poster("poster_c", srgb(90, 150, 120), srgb(230, 210, 120)), Category::Poster);
  // Sideboard, plant and poster on the x = 5 wall; lamp in the corner.
  b.box_between("sideboard", {4.55f, 1.6f, 0.0f}, {5.0f, 2.8f, 0.78f}, oak, Category::Cabinet);
  b.sphere("sideboard_bowl", {4.75f, 2.4f, 0.86f}, 0.08f, metal, Category::Sculpture);
  b.rect("poster_right", {4.995f, 2.2f, 1.6f}, {-1, 0, 0}, {0, 0, 1}, 1.1f, 0.75f,
         poster("poster_d", srgb(200, 80, 60), srgb(40, 40, 90)), Category::Poster);
  b.plant("plant", {4.6f, 3.55f}, 0.17f, pot, leaves);
  b.floor_lamp("lamp", {4.55f, 0.45f}, 1.75f, metal, shade, srgb(255, 225, 180) * 0.7f);
  // Ceiling panels with lights just below them.
  b.rect("ceiling_panel0", {1.6f, 2.0f, 2.695f}, {0, 0, -1}, {0, 1, 0}, 0.6f, 0.6f, panel, Category::Lamp);
  b.rect("ceiling_panel1", {3.4f, 2.0f, 2.695f}, {0, 0, -1}, {0, 1, 0}, 0.6f, 0.6f, panel, Category::Lamp);
  b.light({1.6f, 2.0f, 2.5f}, Color(0.85f, 0.83f, 0.8f), 2.2f);
  b.light({3.4f, 2.0f, 2.5f}, Color(0.85f, 0.83f, 0.8f), 2.2f);
  b.scene().ambient = Color(0.28f, 0.27f, 0.26f);
  b.scene().exposure = 1.6f;

  SceneSpec spec{b.finish(), {}};
  spec.waypoints = {
      {{1.0, 1.35, 1.45}, {2.5, 4.0, 0.8}},   // TV and the floor in front of it
      {{2.4, 1.15, 1.55}, {2.6, 3.4, 0.3}},   // floor reflections of the cabinet
      {{3.9, 1.35, 1.45}, {0.6, 2.6, 0.7}},   // across the glossy table to the shelf
      {{4.0, 2.55, 1.35}, {1.4, 0.6, 0.3}},   // sofa and rug
      {{3.1, 3.05, 1.5}, {2.4, 0.3, 0.7}},    // back towards the sofa
      {{1.7, 3.05, 1.4}, {4.6, 1.6, 0.4}},    // sideboard over the floor
      {{0.95, 2.4, 1.5}, {3.4, 3.9, 1.0}},    // TV screen at an angle
  };
  return spec;
}

}  // namespace rrg::synth
