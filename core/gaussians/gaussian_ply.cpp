#include "core/gaussians/gaussian_ply.h"

#include "core/io/atomic_file.h"

#include <nlohmann/json.hpp>

#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rrg {

namespace {

static_assert(std::endian::native == std::endian::little, "gaussian_ply assumes a little-endian host");

struct Property {
  std::string name;
  std::string type;
  size_t offset = 0;
};

size_t type_size(const std::string& t) {
  if (t == "float" || t == "float32" || t == "int" || t == "int32" || t == "uint" || t == "uint32") return 4;
  if (t == "double" || t == "float64") return 8;
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  return 0;
}

double read_value(const char* p, const std::string& t) {
  if (t == "float" || t == "float32") { float v; std::memcpy(&v, p, 4); return v; }
  if (t == "double" || t == "float64") { double v; std::memcpy(&v, p, 8); return v; }
  if (t == "int" || t == "int32") { int32_t v; std::memcpy(&v, p, 4); return v; }
  if (t == "uint" || t == "uint32") { uint32_t v; std::memcpy(&v, p, 4); return v; }
  if (t == "short" || t == "int16") { int16_t v; std::memcpy(&v, p, 2); return v; }
  if (t == "ushort" || t == "uint16") { uint16_t v; std::memcpy(&v, p, 2); return v; }
  if (t == "char" || t == "int8") return double(int8_t(*p));
  return double(uint8_t(*p));
}

}  // namespace

std::string gaussian_ply_header(size_t count, int sh_degree, bool with_plane_ids) {
  const int rest = 3 * (sh_coeff_count(sh_degree) - 1);
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\nelement vertex " << count << "\n";
  for (const char* n : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"}) h << "property float " << n << "\n";
  for (int j = 0; j < rest; ++j) h << "property float f_rest_" << j << "\n";
  h << "property float opacity\n";
  for (int j = 0; j < 3; ++j) h << "property float scale_" << j << "\n";
  for (int j = 0; j < 4; ++j) h << "property float rot_" << j << "\n";
  if (with_plane_ids) h << "property int plane_id\n";
  h << "end_header\n";
  return h.str();
}

void write_gaussian_ply(const std::filesystem::path& path, const GaussianHost& g, bool with_plane_ids) {
  g.validate();
  const int K = g.sh_coeffs();
  const size_t n = g.size();
  const std::string header = gaussian_ply_header(n, g.sh_degree, with_plane_ids);
  const size_t floats = 9 + size_t(3 * (K - 1)) + 1 + 3 + 4;
  const size_t stride = floats * 4 + (with_plane_ids ? 4 : 0);
  std::vector<char> body(n * stride);
  for (size_t i = 0; i < n; ++i) {
    std::vector<float> f;
    f.reserve(floats);
    for (int c = 0; c < 3; ++c) f.push_back(g.means[i][c]);
    f.insert(f.end(), {0.0f, 0.0f, 0.0f});
    for (int c = 0; c < 3; ++c) f.push_back(g.sh[i * K][c]);
    for (int c = 0; c < 3; ++c)
      for (int k = 1; k < K; ++k) f.push_back(g.sh[i * K + size_t(k)][c]);
    f.push_back(g.logit_opacities[i]);
    for (int c = 0; c < 3; ++c) f.push_back(g.log_scales[i][c]);
    for (int c = 0; c < 4; ++c) f.push_back(g.quats[i][c]);
    char* row = body.data() + i * stride;
    std::memcpy(row, f.data(), floats * 4);
    if (with_plane_ids) std::memcpy(row + floats * 4, &g.plane_ids[i], 4);
  }
  io::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(header.data(), std::streamsize(header.size()));
    out.write(body.data(), std::streamsize(body.size()));
    if (!out) throw std::runtime_error("write_gaussian_ply: cannot write " + tmp.string());
  });
}

GaussianHost read_gaussian_ply(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("read_gaussian_ply: cannot open " + path.string());
  auto fail = [&](const std::string& why) { throw std::runtime_error("read_gaussian_ply: " + path.string() + ": " + why); };
  std::string line;
  std::getline(in, line);
  if (line != "ply") fail("not a PLY file");
  size_t count = 0, stride = 0;
  bool in_vertex = false, binary = false;
  std::vector<Property> props;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "end_header") break;
    if (word == "format") {
      std::string fmt;
      ls >> fmt;
      binary = fmt == "binary_little_endian";
    } else if (word == "element") {
      std::string name;
      size_t c = 0;
      ls >> name >> c;
      if (in_vertex && name != "vertex") fail("elements after 'vertex' are not supported");
      in_vertex = name == "vertex";
      if (in_vertex) count = c;
    } else if (word == "property" && in_vertex) {
      Property p;
      ls >> p.type;
      if (p.type == "list") fail("list properties in 'vertex' are not supported");
      ls >> p.name;
      const size_t sz = type_size(p.type);
      if (sz == 0) fail("unknown property type '" + p.type + "'");
      p.offset = stride;
      stride += sz;
      props.push_back(p);
    }
  }
  if (!binary) fail("only binary_little_endian PLY is supported");
  auto find = [&](const std::string& name) -> const Property* {
    for (const Property& p : props)
      if (p.name == name) return &p;
    return nullptr;
  };
  int rest = 0;
  while (find("f_rest_" + std::to_string(rest))) ++rest;
  int degree = -1;
  for (int d = 0; d <= kMaxShDegree; ++d)
    if (3 * (sh_coeff_count(d) - 1) == rest) degree = d;
  if (degree < 0) fail(std::to_string(rest) + " f_rest properties match no SH degree 0-3");
  std::vector<const Property*> need;
  for (const char* n : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2", "rot_0",
                        "rot_1", "rot_2", "rot_3"}) {
    const Property* p = find(n);
    if (!p) fail(std::string("missing property '") + n + "'");
    need.push_back(p);
  }
  const Property* plane = find("plane_id");
  std::vector<const Property*> rest_props;
  for (int j = 0; j < rest; ++j) rest_props.push_back(find("f_rest_" + std::to_string(j)));
  std::vector<char> body(count * stride);
  in.read(body.data(), std::streamsize(body.size()));
  if (size_t(in.gcount()) != body.size()) fail("file ends before its " + std::to_string(count) + " vertices");
  GaussianHost g(degree);
  g.resize(count);
  const int K = g.sh_coeffs();
  for (size_t i = 0; i < count; ++i) {
    const char* row = body.data() + i * stride;
    auto val = [&](const Property* p) { return float(read_value(row + p->offset, p->type)); };
    g.means[i] = {val(need[0]), val(need[1]), val(need[2])};
    g.sh[i * K] = {val(need[3]), val(need[4]), val(need[5])};
    for (int c = 0; c < 3; ++c)
      for (int k = 1; k < K; ++k) g.sh[i * K + size_t(k)][c] = val(rest_props[size_t(c * (K - 1) + k - 1)]);
    g.logit_opacities[i] = val(need[6]);
    g.log_scales[i] = {val(need[7]), val(need[8]), val(need[9])};
    g.quats[i] = {val(need[10]), val(need[11]), val(need[12]), val(need[13])};
    g.plane_ids[i] = plane ? int32_t(read_value(row + plane->offset, plane->type)) : 0;
  }
  return g;
}

std::filesystem::path planes_json_path(const std::filesystem::path& ply) {
  std::filesystem::path p = ply;
  p.replace_extension(".planes.json");
  return p;
}

void write_reflection_ply(const std::filesystem::path& path, const GaussianHost& g,
                          std::span<const ReflectivePlane> planes) {
  write_gaussian_ply(path, g, true);
  nlohmann::json list = nlohmann::json::array();
  for (const ReflectivePlane& p : planes)
    list.push_back({{"id", p.id}, {"normal", {p.plane.x(), p.plane.y(), p.plane.z()}}, {"offset", p.plane.w()}});
  const nlohmann::json j = {{"convention", "normal . x + offset = 0, world frame, metres"}, {"planes", list}};
  const std::string text = j.dump(1) + "\n";
  io::write_atomically(planes_json_path(path), [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error("write_reflection_ply: cannot write " + tmp.string());
  });
}

std::vector<ReflectivePlane> read_planes_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("read_planes_json: cannot open " + path.string());
  std::vector<ReflectivePlane> out;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& p : j.at("planes")) {
      ReflectivePlane r;
      r.id = p.at("id").get<int32_t>();
      const auto n = p.at("normal");
      r.plane = {n.at(0).get<float>(), n.at(1).get<float>(), n.at(2).get<float>(), p.at("offset").get<float>()};
      out.push_back(r);
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("read_planes_json: " + path.string() + ": " + e.what());
  }
  return out;
}

}  // namespace rrg
