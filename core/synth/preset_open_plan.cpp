// open_plan: a 12 x 9 x 2.8 m open-plan flat (108 m² of floor), the scale of the TSDF's streaming
// (a map larger than the device holds at 1 cm). A polished concrete floor throughout; lounge
// (x < 5, y < 4.5) with a glossy TV screen and coffee table, kitchen along the y = 9 wall with a
// glossy island worktop, dining table, a study alcove behind a partition (x > 9, y > 6.5), and an
// entrance hall with a sideboard and shelves.
#include "core/synth/presets.h"
#include "core/synth/scene_builder.h"

#include <cmath>

namespace rrg::synth {

SceneSpec make_open_plan(uint32_t seed) {
  SceneBuilder b("open_plan", preset_list()[3].description, seed);
  const Color Z = Color::Zero();
  // Materials: F0 > 0 on the floor, the TV screen, the coffee table and the island's worktop.
  const auto floor = b.material("polished_concrete", tex(TextureKind::Plaster, srgb(150, 148, 142), srgb(120, 118, 112),
                                                         srgb(90, 88, 84), 0.8f), 0.15f, 0.04f);
  const auto walls = b.material("painted_wall", tex(TextureKind::Wallpaper, srgb(222, 216, 204), srgb(200, 192, 178),
                                                    srgb(160, 150, 136), 0.45f));
  const auto ceiling = b.material("plaster", tex(TextureKind::Plaster, srgb(238, 236, 230), Z, Z, 1.0f));
  const auto partition = b.material("partition", tex(TextureKind::Wallpaper, srgb(170, 190, 200), srgb(150, 172, 184),
                                                     srgb(110, 130, 140), 0.3f));
  const auto oak = b.material("oak", tex(TextureKind::Wood, srgb(170, 120, 78), srgb(120, 78, 46), srgb(60, 40, 25), 0.2f));
  const auto walnut_gloss = b.material("lacquered_walnut", tex(TextureKind::Wood, srgb(120, 76, 48), srgb(80, 48, 30),
                                                               srgb(40, 26, 18), 0.3f), 0.2f, 0.02f);
  const auto worktop = b.material("quartz_worktop", tex(TextureKind::Tiles, srgb(60, 62, 66), srgb(48, 50, 54),
                                                        srgb(30, 30, 32), 0.6f, 0.002f), 0.2f, 0.02f);
  const auto units = b.material("kitchen_units", tex(TextureKind::Checker, srgb(225, 228, 226), srgb(210, 214, 212), Z, 0.6f));
  const auto fabric = b.material("sofa_fabric", tex(TextureKind::Fabric, srgb(90, 110, 80), srgb(70, 88, 62), Z, 0.1f));
  const auto cushion = b.material("cushion", tex(TextureKind::Fabric, srgb(210, 170, 70), srgb(180, 130, 40), Z, 0.1f));
  const auto books = b.material("books", tex(TextureKind::Books, srgb(230, 220, 190), Z, srgb(30, 25, 20), 0.04f));
  const auto metal = b.material("steel", tex(TextureKind::Metal, srgb(150, 150, 155), Z, Z, 0.1f));
  const auto black = b.material("black_plastic", tex(TextureKind::Solid, srgb(30, 30, 32), Z, Z, 0.1f));
  const auto screen = b.material("tv_screen", tex(TextureKind::Screen, srgb(40, 90, 160), srgb(200, 120, 60),
                                                  srgb(8, 8, 10), 1.0f), 0.12f, 0.0f);
  const auto monitor = b.material("matte_screen", tex(TextureKind::Screen, srgb(60, 120, 200), srgb(230, 230, 240),
                                                      srgb(15, 15, 18), 1.0f));
  const auto seat = b.material("seat_fabric", tex(TextureKind::Fabric, srgb(40, 60, 90), srgb(25, 40, 65), Z, 0.1f));
  const auto rug = b.material("rug", tex(TextureKind::Carpet, srgb(60, 70, 130), srgb(200, 190, 150), Z, 0.25f));
  const HomeMaterials home = home_materials(b);
  const auto shade = home.lamp_shade, panel = home.light_panel, pot = home.terracotta, leaves = home.leaves,
             door = home.door;
  auto poster = [&](const std::string& n, Color a, Color c2) {
    return b.material(n, tex(TextureKind::Poster, a, c2, srgb(20, 20, 20), 1.0f));
  };

  b.room({12.0f, 9.0f, 2.8f}, floor, walls, ceiling);
  // Lounge: TV on the y = 0 wall, sofa facing it, coffee table on a rug.
  b.box_between("tv_cabinet", {1.2f, 0.0f, 0.0f}, {3.4f, 0.45f, 0.5f}, oak, Category::Cabinet);
  b.box_between("tv_body", {1.5f, 0.03f, 0.72f}, {3.1f, 0.12f, 1.64f}, black, Category::Tv);
  b.rect("tv_screen", {2.3f, 0.125f, 1.18f}, {0, 1, 0}, {0, 0, 1}, 1.5f, 0.84f, screen, Category::Tv);
  b.sofa("sofa", {1.0f, 3.0f}, {3.6f, 3.9f}, {0, -1}, fabric, cushion, Category::Sofa);
  b.rect("rug", {2.3f, 1.9f, 0.004f}, {0, 0, 1}, {0, 1, 0}, 2.2f, 1.4f, rug, Category::Rug);
  b.table("coffee_table", {2.3f, 1.9f}, {1.2f, 0.6f, 0.05f}, 0.45f, walnut_gloss, metal, Category::Table);
  b.rect("poster_lounge", {0.005f, 2.2f, 1.6f}, {1, 0, 0}, {0, 0, 1}, 1.2f, 0.8f,
         poster("poster_a", srgb(230, 200, 120), srgb(60, 90, 140)), Category::Poster);
  b.floor_lamp("lamp", {0.4f, 3.9f}, 1.75f, metal, shade, srgb(255, 225, 180) * 0.7f);
  // Kitchen: units along the y = 9 wall with wall cupboards, an island with a glossy worktop.
  b.box_between("kitchen_units", {0.0f, 8.4f, 0.0f}, {4.6f, 9.0f, 0.88f}, units, Category::Cabinet);
  b.box_between("kitchen_counter", {0.0f, 8.38f, 0.88f}, {4.6f, 9.0f, 0.92f}, black, Category::Cabinet);
  b.box_between("wall_cupboards", {0.0f, 8.65f, 1.5f}, {4.6f, 9.0f, 2.2f}, units, Category::Cabinet);
  b.box_between("island", {1.4f, 6.2f, 0.0f}, {3.6f, 7.1f, 0.88f}, units, Category::Cabinet);
  b.rect("island_worktop", {2.5f, 6.65f, 0.885f}, {0, 0, 1}, {0, 1, 0}, 2.2f, 0.9f, worktop, Category::Table);
  b.cylinder("fruit_bowl", {3.0f, 6.7f, 0.885f}, 0.14f, 0.08f, metal, Category::Sculpture);
  b.plant("kitchen_plant", {0.35f, 5.6f}, 0.16f, pot, leaves);
  // Dining table with four chairs.
  b.table("dining_table", {6.2f, 7.3f}, {1.8f, 0.9f, 0.04f}, 0.75f, oak, metal, Category::Table);
  b.chair("dining_chair0", {5.6f, 6.55f}, {0, 1}, seat, metal);
  b.chair("dining_chair1", {6.8f, 6.55f}, {0, 1}, seat, metal);
  b.chair("dining_chair2", {5.6f, 8.05f}, {0, -1}, seat, metal);
  b.chair("dining_chair3", {6.8f, 8.05f}, {0, -1}, seat, metal);
  b.rect("poster_dining", {6.2f, 8.995f, 1.65f}, {0, -1, 0}, {0, 0, 1}, 1.4f, 0.9f,
         poster("poster_b", srgb(240, 230, 210), srgb(160, 60, 50)), Category::Poster);
  // Study alcove behind a partition wall at x = 9 (y 6.5 to 9): desk, monitor, chair, shelves.
  b.box_between("partition", {8.94f, 6.5f, 0.0f}, {9.06f, 9.0f, 2.8f}, partition, Category::Wall);
  b.table("desk", {11.55f, 7.8f}, {0.8f, 1.5f, 0.04f}, 0.74f, oak, metal, Category::Desk);
  b.box("monitor_stand", {11.8f, 7.8f, 0.82f}, {0.06f, 0.06f, 0.16f}, metal, Category::Monitor);
  b.box("monitor", {11.8f, 7.8f, 1.06f}, {0.04f, 0.62f, 0.38f}, black, Category::Monitor);
  b.rect("monitor_screen", {11.7795f, 7.8f, 1.07f}, {-1, 0, 0}, {0, 0, 1}, 0.56f, 0.32f, monitor, Category::Monitor);
  b.chair("desk_chair", {10.9f, 7.8f}, {1, 0}, seat, metal);
  b.bookshelf("study_shelf", {9.3f, 8.64f, 0.0f}, {10.9f, 9.0f, 2.0f}, 4, {0, -1, 0}, oak, books);
  // Entrance hall: door and shelves on the y = 0 wall, sideboard on the x = 12 wall.
  b.rect("front_door", {10.6f, 0.005f, 1.025f}, {0, 1, 0}, {0, 0, 1}, 0.95f, 2.05f, door, Category::Door);
  b.bookshelf("hall_shelf", {6.4f, 0.0f, 0.0f}, {8.4f, 0.36f, 2.0f}, 3, {0, 1, 0}, oak, books);
  b.box_between("sideboard", {11.55f, 2.0f, 0.0f}, {12.0f, 3.6f, 0.8f}, oak, Category::Cabinet);
  b.sphere("sideboard_vase", {11.78f, 2.5f, 0.92f}, 0.12f, pot, Category::Sculpture);
  b.rect("poster_hall", {11.995f, 2.8f, 1.6f}, {-1, 0, 0}, {0, 0, 1}, 1.1f, 0.75f,
         poster("poster_c", srgb(90, 150, 120), srgb(230, 210, 120)), Category::Poster);
  b.plant("hall_plant", {11.6f, 4.6f}, 0.18f, pot, leaves);
  // Ceiling panels with lights just below them, one per zone.
  const Eigen::Vector2f lights[] = {{2.3f, 2.0f}, {2.5f, 6.8f}, {6.2f, 7.2f}, {10.5f, 7.6f}, {6.5f, 2.5f}, {10.0f, 2.5f}};
  int k = 0;
  for (const Eigen::Vector2f& l : lights) {
    const std::string n = std::to_string(k++);
    b.rect("ceiling_panel" + n, {l.x(), l.y(), 2.795f}, {0, 0, -1}, {0, 1, 0}, 0.6f, 0.6f, panel, Category::Lamp);
    b.light({l.x(), l.y(), 2.6f}, Color(0.85f, 0.83f, 0.8f), 2.4f);
  }
  b.scene().ambient = Color(0.28f, 0.27f, 0.26f);
  b.scene().exposure = 1.6f;

  SceneSpec spec{b.finish(), {}};
  // An ellipse round the middle of the flat, looking out at the nearer walls (2.7 to 4.5 m away,
  // within a depth sensor's range): the view turns through every zone once per loop, 45 degrees
  // per waypoint.
  constexpr double kPi = 3.14159265358979;
  for (int i = 0; i < 8; ++i) {
    const double theta = (90.0 + 45.0 * i) * kPi / 180.0;  // starts facing the dining table and kitchen
    const Eigen::Vector3d eye(6.0 + 3.0 * std::cos(theta), 4.5 + 1.8 * std::sin(theta), 1.5 + 0.05 * std::sin(2 * theta));
    const Eigen::Vector3d target(6.0 + 6.0 * std::cos(theta), 4.5 + 4.5 * std::sin(theta), 0.8);
    spec.waypoints.push_back({eye, target});
  }
  return spec;
}

}  // namespace rrg::synth
