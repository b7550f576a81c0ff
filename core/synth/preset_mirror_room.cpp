// mirror_room: a large framed wall mirror (F0 0.9) on the y = 4 wall and a glossy wooden floor,
// with an armchair, side table, bookshelf, pedestal sculpture, lamp, plant and posters to reflect.
#include "core/synth/presets.h"
#include "core/synth/scene_builder.h"

namespace rrg::synth {

SceneSpec make_mirror_room(uint32_t seed) {
  SceneBuilder b("mirror_room", preset_list()[1].description, seed);
  const Color Z = Color::Zero();
  const auto floor = b.material("glossy_planks", tex(TextureKind::Wood, srgb(196, 150, 104), srgb(150, 104, 66),
                                                     srgb(70, 48, 30), 0.18f), 0.2f, 0.03f);
  const auto walls = b.material("wallpaper", tex(TextureKind::Wallpaper, srgb(190, 204, 196), srgb(160, 180, 172),
                                                 srgb(90, 120, 110), 0.28f));
  const auto ceiling = b.material("plaster", tex(TextureKind::Plaster, srgb(236, 236, 232), Z, Z, 1.0f));
  const auto mirror = b.material("mirror", tex(TextureKind::Metal, srgb(60, 62, 64), Z, Z, 0.1f), 0.9f, 0.0f);
  const auto frame = b.material("gilt_frame", tex(TextureKind::Wood, srgb(190, 150, 70), srgb(140, 100, 40),
                                                  srgb(80, 60, 20), 0.03f));
  const auto velvet = b.material("velvet", tex(TextureKind::Fabric, srgb(140, 40, 50), srgb(100, 25, 35), Z, 0.1f));
  const auto cushion = b.material("cushion", tex(TextureKind::Fabric, srgb(220, 200, 150), srgb(190, 160, 110), Z, 0.1f));
  const auto oak = b.material("oak", tex(TextureKind::Wood, srgb(160, 112, 70), srgb(112, 72, 42), srgb(56, 36, 22), 0.2f));
  const auto marble = b.material("table_marble", tex(TextureKind::Tiles, srgb(235, 235, 230), srgb(205, 205, 200),
                                                     srgb(205, 205, 200), 2.0f, 0.0f), 0.05f, 0.02f);
  const auto books = b.material("books", tex(TextureKind::Books, srgb(230, 220, 190), Z, srgb(30, 25, 20), 0.04f));
  const auto metal = b.material("brass", tex(TextureKind::Metal, srgb(180, 150, 90), Z, Z, 0.1f));
  const auto stone = b.material("stone", tex(TextureKind::Checker, srgb(90, 90, 96), srgb(200, 200, 206), Z, 0.06f));
  const auto pedestal = b.material("pedestal", tex(TextureKind::Plaster, srgb(225, 222, 215), Z, Z, 0.5f));
  const auto shade = b.emitter("lamp_shade", tex(TextureKind::Fabric, srgb(250, 235, 200), srgb(240, 220, 180), Z, 0.1f),
                               srgb(255, 220, 160) * 0.9f);
  const auto panel = b.emitter("light_panel", tex(TextureKind::Solid, srgb(250, 250, 245), Z, Z, 0.1f),
                               Color(1.2f, 1.15f, 1.05f));
  const auto pot = b.material("ceramic", tex(TextureKind::Checker, srgb(40, 70, 120), srgb(220, 220, 230), Z, 0.05f));
  const auto leaves = b.material("leaves", tex(TextureKind::Leaves, srgb(50, 120, 45), srgb(20, 60, 25), Z, 0.1f));
  const auto door = b.material("door", tex(TextureKind::Wood, srgb(210, 200, 185), srgb(180, 170, 150), srgb(90, 80, 60), 0.9f));
  auto poster = [&](const std::string& n, Color a, Color c2) {
    return b.material(n, tex(TextureKind::Poster, a, c2, srgb(20, 20, 20), 1.0f));
  };

  b.room({5.0f, 4.0f, 2.7f}, floor, walls, ceiling);
  // The mirror wall (y = 4) and its frame.
  b.rect("mirror", {2.5f, 3.985f, 1.35f}, {0, -1, 0}, {0, 0, 1}, 2.6f, 1.6f, mirror, Category::Mirror);
  b.box_between("mirror_frame_top", {1.12f, 3.95f, 2.15f}, {3.88f, 4.0f, 2.23f}, frame, Category::Mirror);
  b.box_between("mirror_frame_bottom", {1.12f, 3.95f, 0.47f}, {3.88f, 4.0f, 0.55f}, frame, Category::Mirror);
  b.box_between("mirror_frame_left", {1.12f, 3.95f, 0.55f}, {1.2f, 4.0f, 2.15f}, frame, Category::Mirror);
  b.box_between("mirror_frame_right", {3.8f, 3.95f, 0.55f}, {3.88f, 4.0f, 2.15f}, frame, Category::Mirror);
  // Seating corner facing the mirror, with a marble-topped side table.
  b.sofa("armchair", {0.45f, 0.3f}, {1.45f, 1.2f}, {0, 1}, velvet, cushion, Category::Sofa);
  b.table("side_table", {1.95f, 0.6f}, {0.55f, 0.55f, 0.04f}, 0.55f, marble, metal, Category::Table);
  b.box("side_table_books", {1.9f, 0.55f, 0.585f}, {0.24f, 0.18f, 0.07f}, books, Category::Books, -20.0f);
  // Pedestal sculpture in the middle of the room.
  b.box_between("pedestal", {2.45f, 1.95f, 0.0f}, {2.8f, 2.3f, 0.9f}, pedestal, Category::Sculpture);
  b.sphere("sculpture", {2.625f, 2.125f, 1.06f}, 0.16f, stone, Category::Sculpture);
  // Bookshelf on the x = 5 wall, plant and lamp in the corners, door on y = 0.
  b.bookshelf("bookshelf", {4.64f, 0.9f, 0.0f}, {5.0f, 2.3f, 1.9f}, 3, {-1, 0, 0}, oak, books);
  b.plant("plant", {4.55f, 3.5f}, 0.18f, pot, leaves);
  b.floor_lamp("lamp", {0.45f, 3.5f}, 1.7f, metal, shade, srgb(255, 225, 180) * 0.7f);
  b.rect("door", {4.4f, 0.005f, 1.025f}, {0, 1, 0}, {0, 0, 1}, 0.9f, 2.05f, door, Category::Door);
  b.rect("poster_left", {0.005f, 2.1f, 1.5f}, {1, 0, 0}, {0, 0, 1}, 1.2f, 0.8f,
         poster("poster_a", srgb(240, 200, 90), srgb(30, 80, 130)), Category::Poster);
  b.rect("poster_back", {2.7f, 0.005f, 1.55f}, {0, 1, 0}, {0, 0, 1}, 1.1f, 0.75f,
         poster("poster_b", srgb(120, 180, 200), srgb(200, 60, 90)), Category::Poster);
  b.rect("ceiling_panel0", {1.6f, 2.0f, 2.695f}, {0, 0, -1}, {0, 1, 0}, 0.6f, 0.6f, panel, Category::Lamp);
  b.rect("ceiling_panel1", {3.4f, 2.0f, 2.695f}, {0, 0, -1}, {0, 1, 0}, 0.6f, 0.6f, panel, Category::Lamp);
  b.light({1.6f, 2.0f, 2.5f}, Color(0.85f, 0.83f, 0.8f), 2.2f);
  b.light({3.4f, 2.0f, 2.5f}, Color(0.85f, 0.83f, 0.8f), 2.2f);
  b.scene().ambient = Color(0.28f, 0.27f, 0.26f);
  b.scene().exposure = 1.6f;

  SceneSpec spec{b.finish(), {}};
  spec.waypoints = {
      {{1.2, 1.9, 1.5}, {2.3, 4.0, 1.1}},   // the mirror, slightly from the left
      {{2.0, 1.35, 1.55}, {2.8, 4.0, 0.9}}, // mirror and the floor in front of it
      {{3.5, 1.3, 1.45}, {2.0, 4.0, 1.2}},  // mirror from the right
      {{4.0, 2.3, 1.5}, {1.0, 3.6, 0.8}},   // lamp corner, mirror at a grazing angle
      {{3.4, 3.1, 1.45}, {0.4, 1.2, 0.8}},  // the armchair corner over the glossy floor
      {{2.6, 3.2, 1.5}, {2.0, 0.0, 0.7}},   // the door wall and its poster
      {{1.8, 3.15, 1.5}, {4.0, 0.6, 0.7}},  // the bookshelf
      {{0.95, 2.7, 1.5}, {4.2, 3.7, 1.0}},  // the mirror from the left wall
  };
  return spec;
}

}  // namespace rrg::synth
