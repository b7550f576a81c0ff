// office: the matte control scene (F0 = 0 everywhere): three desks with monitors and chairs,
// a bookshelf and filing cabinets, whiteboards, posters and a carpet-tiled floor.
#include "core/synth/presets.h"
#include "core/synth/scene_builder.h"

#include <cmath>

namespace rrg::synth {

SceneSpec make_office(uint32_t seed) {
  SceneBuilder b("office", preset_list()[2].description, seed);
  const Color Z = Color::Zero();
  const auto floor = b.material("carpet_tiles", tex(TextureKind::Carpet, srgb(90, 100, 115), srgb(130, 140, 150), Z, 0.5f));
  const auto walls = b.material("painted_wall", tex(TextureKind::Wallpaper, srgb(215, 215, 208), srgb(200, 200, 192),
                                                    srgb(170, 170, 165), 0.4f));
  const auto ceiling = b.material("ceiling_tiles", tex(TextureKind::Tiles, srgb(235, 235, 230), srgb(225, 225, 220),
                                                       srgb(170, 170, 170), 0.6f, 0.02f));
  const auto desk = b.material("desk_laminate", tex(TextureKind::Wood, srgb(205, 180, 140), srgb(180, 150, 110),
                                                    srgb(120, 100, 70), 0.35f));
  const auto frame = b.material("grey_metal", tex(TextureKind::Metal, srgb(110, 112, 118), Z, Z, 0.1f));
  const auto seat = b.material("seat_fabric", tex(TextureKind::Fabric, srgb(40, 60, 90), srgb(25, 40, 65), Z, 0.1f));
  const auto black = b.material("black_plastic", tex(TextureKind::Solid, srgb(35, 35, 38), Z, Z, 0.1f));
  const auto screen = b.material("matte_screen", tex(TextureKind::Screen, srgb(60, 120, 200), srgb(230, 230, 240),
                                                     srgb(15, 15, 18), 1.0f));
  const auto whiteboard = b.material("whiteboard", tex(TextureKind::Whiteboard, srgb(240, 242, 240), Z,
                                                       srgb(160, 160, 165), 1.0f));
  const auto shelf = b.material("shelf_board", tex(TextureKind::Wood, srgb(220, 210, 190), srgb(195, 185, 165),
                                                   srgb(120, 110, 90), 0.2f));
  const auto books = b.material("binders", tex(TextureKind::Books, srgb(240, 240, 240), Z, srgb(30, 30, 30), 0.04f));
  const auto cabinet = b.material("cabinet", tex(TextureKind::Checker, srgb(150, 155, 160), srgb(140, 145, 150), Z, 0.36f));
  const auto panel = b.emitter("light_panel", tex(TextureKind::Solid, srgb(250, 250, 250), Z, Z, 0.1f),
                               Color(1.2f, 1.2f, 1.15f));
  const auto pot = b.material("pot", tex(TextureKind::Plaster, srgb(230, 230, 225), Z, Z, 0.2f));
  const auto leaves = b.material("leaves", tex(TextureKind::Leaves, srgb(50, 120, 45), srgb(20, 60, 25), Z, 0.1f));
  const auto door = b.material("door", tex(TextureKind::Wood, srgb(200, 190, 170), srgb(175, 165, 145), srgb(90, 80, 60), 0.9f));
  auto poster = [&](const std::string& n, Color a, Color c2) {
    return b.material(n, tex(TextureKind::Poster, a, c2, srgb(25, 25, 25), 1.0f));
  };

  b.room({5.0f, 4.0f, 2.7f}, floor, walls, ceiling);
  // Two desks against the y = 0 wall, one against x = 5; a monitor and a chair at each.
  struct DeskSpec { const char* name; Eigen::Vector2f centre; float yaw; };
  const DeskSpec desks[] = {{"desk0", {0.95f, 0.45f}, 0.0f}, {"desk1", {3.15f, 0.45f}, 0.0f}, {"desk2", {4.6f, 2.6f}, 90.0f}};
  for (const DeskSpec& d : desks) {
    const std::string n = d.name;
    b.table(n, d.centre, {1.4f, 0.7f, 0.04f}, 0.74f, desk, frame, Category::Desk, d.yaw);
    const bool along_x = d.yaw == 0.0f;
    // Monitor near the wall side of the desk, facing the room.
    const Eigen::Vector2f back = along_x ? Eigen::Vector2f(d.centre.x(), d.centre.y() - 0.15f)
                                         : Eigen::Vector2f(d.centre.x() + 0.15f, d.centre.y());
    const Eigen::Vector3f facing = along_x ? Eigen::Vector3f(0, 1, 0) : Eigen::Vector3f(-1, 0, 0);
    b.box(n + "_monitor_stand", {back.x(), back.y(), 0.82f}, {0.06f, 0.06f, 0.16f}, frame, Category::Monitor);
    b.box(n + "_monitor", {back.x(), back.y(), 1.06f}, along_x ? Eigen::Vector3f(0.62f, 0.04f, 0.38f)
                                                               : Eigen::Vector3f(0.04f, 0.62f, 0.38f),
          black, Category::Monitor);
    const Eigen::Vector3f screen_c = Eigen::Vector3f(back.x(), back.y(), 1.07f) + facing * 0.0205f;
    b.rect(n + "_screen", screen_c, facing, {0, 0, 1}, 0.56f, 0.32f, screen, Category::Monitor);
    const Eigen::Vector2f chair_c = d.centre + Eigen::Vector2f(facing.x(), facing.y()) * 0.75f;
    b.chair(n + "_chair", chair_c, -Eigen::Vector2f(facing.x(), facing.y()), seat, frame);
  }
  // Shelf and filing cabinets on the x = 0 wall.
  b.bookshelf("bookshelf", {0.0f, 1.6f, 0.0f}, {0.36f, 2.8f, 2.0f}, 4, {1, 0, 0}, shelf, books);
  b.box_between("cabinet0", {0.0f, 3.0f, 0.0f}, {0.5f, 3.45f, 1.1f}, cabinet, Category::Cabinet);
  b.box_between("cabinet1", {0.0f, 3.47f, 0.0f}, {0.5f, 3.92f, 1.1f}, cabinet, Category::Cabinet);
  // Whiteboard and door on y = 4, whiteboard and posters elsewhere.
  b.rect("whiteboard0", {2.2f, 3.995f, 1.45f}, {0, -1, 0}, {0, 0, 1}, 2.0f, 1.1f, whiteboard, Category::Whiteboard);
  b.rect("door", {4.2f, 3.995f, 1.025f}, {0, -1, 0}, {0, 0, 1}, 0.9f, 2.05f, door, Category::Door);
  b.rect("whiteboard1", {4.995f, 1.0f, 1.5f}, {-1, 0, 0}, {0, 0, 1}, 1.2f, 0.9f, whiteboard, Category::Whiteboard);
  b.rect("poster0", {2.05f, 0.005f, 1.65f}, {0, 1, 0}, {0, 0, 1}, 0.7f, 0.5f,
         poster("poster_a", srgb(200, 220, 240), srgb(40, 60, 120)), Category::Poster);
  b.rect("poster1", {4.995f, 3.3f, 1.6f}, {-1, 0, 0}, {0, 0, 1}, 0.6f, 0.8f,
         poster("poster_b", srgb(240, 220, 160), srgb(120, 40, 40)), Category::Poster);
  b.plant("plant", {4.6f, 0.35f}, 0.16f, pot, leaves);
  b.rect("ceiling_panel0", {1.6f, 2.0f, 2.695f}, {0, 0, -1}, {0, 1, 0}, 1.2f, 0.6f, panel, Category::Lamp);
  b.rect("ceiling_panel1", {3.4f, 2.0f, 2.695f}, {0, 0, -1}, {0, 1, 0}, 1.2f, 0.6f, panel, Category::Lamp);
  b.light({1.6f, 2.0f, 2.5f}, Color(0.9f, 0.9f, 0.88f), 2.4f);
  b.light({3.4f, 2.0f, 2.5f}, Color(0.9f, 0.9f, 0.88f), 2.4f);
  b.scene().ambient = Color(0.3f, 0.3f, 0.3f);
  b.scene().exposure = 1.6f;

  SceneSpec spec{b.finish(), {}};
  // An ellipse round the free middle of the room, looking across it: the view sweeps the
  // whiteboard / door wall, the shelves and cabinets, the desks and desk 2, turning 45 degrees per
  // waypoint.
  constexpr double kPi = 3.14159265358979;
  for (int i = 0; i < 8; ++i) {
    const double theta = (90.0 + 45.0 * i) * kPi / 180.0;  // starts at the back, facing the desks
    const Eigen::Vector3d eye(2.5 + 1.3 * std::cos(theta), 2.2 + 0.8 * std::sin(theta), 1.5 + 0.05 * std::sin(2 * theta));
    const Eigen::Vector3d target(2.5 - 2.0 * std::cos(theta), 2.2 - 1.4 * std::sin(theta), 0.8);
    spec.waypoints.push_back({eye, target});
  }
  return spec;
}

}  // namespace rrg::synth
