// PLY meshes: a binary little-endian writer and an ascii / binary_little_endian reader that takes
// any scalar type (char..double) for any property and 'vertex_indices' / 'vertex_index' face lists.
#include "core/io/ply.h"

#include "core/io/atomic_file.h"

#include <spdlog/spdlog.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;
static_assert(std::endian::native == std::endian::little, "PLY I/O assumes a little-endian host");

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;  // the item type for lists
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> properties;
};

PlyType parse_type(const std::string& name, const fs::path& path) {
  static const std::map<std::string, PlyType> types = {
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},     {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},   {"short", PlyType::Int16},   {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16}, {"uint16", PlyType::UInt16}, {"int", PlyType::Int32},
      {"int32", PlyType::Int32},   {"uint", PlyType::UInt32},   {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  const auto it = types.find(name);
  if (it == types.end()) throw std::runtime_error(path.string() + ": unknown PLY property type '" + name + "'");
  return it->second;
}

size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::Int8: case PlyType::UInt8: return 1;
    case PlyType::Int16: case PlyType::UInt16: return 2;
    case PlyType::Int32: case PlyType::UInt32: case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 0;
}

// Reads successive values from the body, ascii or binary little endian.
class BodyReader {
 public:
  BodyReader(const std::string& data, size_t offset, bool binary, const fs::path& path)
      : data_(data), pos_(offset), binary_(binary), path_(path) {}

  double next(PlyType type) { return binary_ ? next_binary(type) : next_ascii(); }
  void set_context(const std::string& element, size_t index) { element_ = element, index_ = index; }

 private:
  template <class T>
  double load() {
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return double(v);
  }
  double next_binary(PlyType type) {
    if (pos_ + type_size(type) > data_.size()) truncated();
    switch (type) {
      case PlyType::Int8: return load<int8_t>();
      case PlyType::UInt8: return load<uint8_t>();
      case PlyType::Int16: return load<int16_t>();
      case PlyType::UInt16: return load<uint16_t>();
      case PlyType::Int32: return load<int32_t>();
      case PlyType::UInt32: return load<uint32_t>();
      case PlyType::Float32: return load<float>();
      case PlyType::Float64: return load<double>();
    }
    return 0.0;
  }
  double next_ascii() {
    auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (pos_ < data_.size() && space(data_[pos_])) ++pos_;
    if (pos_ >= data_.size()) truncated();
    size_t end = pos_;
    while (end < data_.size() && !space(data_[end])) ++end;
    const char* first = data_.data() + pos_;
    if (*first == '+') ++first;
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(first, data_.data() + end, v);
    if (ec != std::errc() || ptr != data_.data() + end)
      throw std::runtime_error(path_.string() + ": bad number '" + data_.substr(pos_, end - pos_) + "' in element '" +
                               element_ + "' entry " + std::to_string(index_));
    pos_ = end;
    return v;
  }
  [[noreturn]] void truncated() const {
    throw std::runtime_error(path_.string() + ": file ends inside element '" + element_ + "' (entry " +
                             std::to_string(index_) + ")");
  }

  const std::string& data_;
  size_t pos_;
  bool binary_;
  const fs::path& path_;
  std::string element_;
  size_t index_ = 0;
};

std::string read_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw std::runtime_error("PLY file not found: " + path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open PLY file " + path.string());
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("error reading PLY file " + path.string());
  return data;
}

// Parses the header; returns the elements and sets body_offset / binary.
std::vector<PlyElement> parse_header(const std::string& data, const fs::path& path, size_t& body_offset, bool& binary) {
  auto bad = [&](const std::string& why) -> std::runtime_error { return std::runtime_error(path.string() + ": " + why); };
  std::vector<PlyElement> elements;
  size_t pos = 0;
  bool have_format = false;
  for (int line_no = 1;; ++line_no) {
    const size_t eol = data.find('\n', pos);
    if (eol == std::string::npos) throw bad("PLY header has no end_header line");
    std::string line = data.substr(pos, eol - pos);
    pos = eol + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (line_no == 1) {
      if (key != "ply") throw bad("not a PLY file (first line is not 'ply')");
      continue;
    }
    if (key.empty() || key == "comment" || key == "obj_info") continue;
    if (key == "end_header") break;
    if (key == "format") {
      std::string fmt;
      words >> fmt;
      if (fmt == "ascii") binary = false;
      else if (fmt == "binary_little_endian") binary = true;
      else throw bad("unsupported PLY format '" + fmt + "' (ascii and binary_little_endian are read)");
      have_format = true;
    } else if (key == "element") {
      PlyElement e;
      long long count = -1;
      words >> e.name >> count;
      if (e.name.empty() || count < 0) throw bad("bad element line " + std::to_string(line_no) + ": '" + line + "'");
      e.count = size_t(count);
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty()) throw bad("property before any element on header line " + std::to_string(line_no));
      PlyProperty p;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> p.name;
        p.is_list = true;
        p.count_type = parse_type(count_type, path);
        p.type = parse_type(item_type, path);
      } else {
        p.type = parse_type(type, path);
        words >> p.name;
      }
      if (p.name.empty()) throw bad("property without a name on header line " + std::to_string(line_no));
      elements.back().properties.push_back(p);
    } else {
      throw bad("unknown PLY header keyword '" + key + "' on line " + std::to_string(line_no));
    }
  }
  if (!have_format) throw bad("PLY header has no format line");
  body_offset = pos;
  return elements;
}

// Where a vertex property goes; colour scale by stored type (uchar /255, ushort /65535, float as is).
struct VertexSlots {
  int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1, r = -1, g = -1, b = -1, plane = -1;
};

float color_scale(PlyType t) {
  switch (t) {
    case PlyType::Float32: case PlyType::Float64: return 1.0f;
    case PlyType::UInt16: case PlyType::Int16: return 1.0f / 65535.0f;
    default: return 1.0f / 255.0f;
  }
}

void read_vertices(BodyReader& body, const PlyElement& e, TriangleMesh& mesh, const fs::path& path) {
  VertexSlots s;
  for (int i = 0; i < int(e.properties.size()); ++i) {
    const std::string& n = e.properties[i].name;
    if (e.properties[i].is_list) continue;
    if (n == "x") s.x = i; else if (n == "y") s.y = i; else if (n == "z") s.z = i;
    else if (n == "nx") s.nx = i; else if (n == "ny") s.ny = i; else if (n == "nz") s.nz = i;
    else if (n == "red" || n == "r") s.r = i; else if (n == "green" || n == "g") s.g = i;
    else if (n == "blue" || n == "b") s.b = i; else if (n == "plane_id") s.plane = i;
  }
  if (s.x < 0 || s.y < 0 || s.z < 0) throw std::runtime_error(path.string() + ": vertex element has no x, y, z properties");
  const bool normals = s.nx >= 0 && s.ny >= 0 && s.nz >= 0;
  const bool colors = s.r >= 0 && s.g >= 0 && s.b >= 0;
  const bool planes = s.plane >= 0;
  mesh.vertices.resize(e.count);
  if (normals) mesh.normals.resize(e.count);
  if (colors) mesh.colors.resize(e.count);
  if (planes) mesh.plane_ids.resize(e.count);
  std::vector<double> v(e.properties.size());
  for (size_t k = 0; k < e.count; ++k) {
    body.set_context(e.name, k);
    for (size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      if (p.is_list) {
        const auto n = static_cast<long long>(body.next(p.count_type));
        for (long long j = 0; j < n; ++j) body.next(p.type);
      } else {
        v[i] = body.next(p.type);
      }
    }
    mesh.vertices[k] = Eigen::Vector3f(float(v[s.x]), float(v[s.y]), float(v[s.z]));
    if (normals) mesh.normals[k] = Eigen::Vector3f(float(v[s.nx]), float(v[s.ny]), float(v[s.nz]));
    if (colors)
      mesh.colors[k] = Eigen::Vector3f(float(v[s.r]) * color_scale(e.properties[s.r].type),
                                       float(v[s.g]) * color_scale(e.properties[s.g].type),
                                       float(v[s.b]) * color_scale(e.properties[s.b].type));
    if (planes) mesh.plane_ids[k] = static_cast<int32_t>(v[s.plane]);
  }
}

void read_faces(BodyReader& body, const PlyElement& e, TriangleMesh& mesh, const fs::path& path) {
  size_t skipped = 0;
  std::vector<int> poly;
  for (size_t k = 0; k < e.count; ++k) {
    body.set_context(e.name, k);
    for (const PlyProperty& p : e.properties) {
      if (!p.is_list) {
        body.next(p.type);
        continue;
      }
      const double count = body.next(p.count_type);
      if (count < 0) throw std::runtime_error(path.string() + ": face " + std::to_string(k) + " has a negative count");
      const bool indices = p.name == "vertex_indices" || p.name == "vertex_index";
      poly.clear();
      for (long long j = 0; j < static_cast<long long>(count); ++j) {
        const double idx = body.next(p.type);
        if (indices) poly.push_back(static_cast<int>(idx));
      }
      if (!indices) continue;
      if (poly.size() < 3) {
        ++skipped;
        continue;
      }
      for (size_t j = 1; j + 1 < poly.size(); ++j)  // fan split
        mesh.triangles.emplace_back(poly[0], poly[j], poly[j + 1]);
    }
  }
  if (skipped) spdlog::debug("{}: skipped {} faces with fewer than 3 vertices", path.string(), skipped);
}

}  // namespace

TriangleMesh read_ply_mesh(const fs::path& path) {
  const std::string data = read_file(path);
  size_t body_offset = 0;
  bool binary = false;
  const std::vector<PlyElement> elements = parse_header(data, path, body_offset, binary);
  TriangleMesh mesh;
  bool have_vertices = false;
  BodyReader body(data, body_offset, binary, path);
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") {
      read_vertices(body, e, mesh, path);
      have_vertices = true;
    } else if (e.name == "face") {
      read_faces(body, e, mesh, path);
    } else {  // skip unknown elements value by value
      for (size_t k = 0; k < e.count; ++k) {
        body.set_context(e.name, k);
        for (const PlyProperty& p : e.properties) {
          const auto n = p.is_list ? static_cast<long long>(body.next(p.count_type)) : 1;
          for (long long j = 0; j < n; ++j) body.next(p.type);
        }
      }
    }
  }
  if (!have_vertices) throw std::runtime_error(path.string() + ": PLY file has no vertex element");
  try {
    mesh.validate();
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
  return mesh;
}

void write_ply_mesh(const fs::path& path, const TriangleMesh& mesh) {
  try {
    mesh.validate();
  } catch (const std::exception& e) {
    throw std::invalid_argument("cannot write " + path.string() + ": " + e.what());
  }
  const bool normals = !mesh.normals.empty(), colors = !mesh.colors.empty(), planes = !mesh.plane_ids.empty();
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment rrg-slam\n";
  header += "element vertex " + std::to_string(mesh.vertices.size()) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (planes) header += "property int plane_id\n";
  header += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  header += "property list uchar int vertex_indices\nend_header\n";

  std::string body;
  const size_t vsize = 12 + (normals ? 12 : 0) + (colors ? 3 : 0) + (planes ? 4 : 0);
  body.reserve(mesh.vertices.size() * vsize + mesh.triangles.size() * 13);
  auto put = [&body](const auto& value) { body.append(reinterpret_cast<const char*>(&value), sizeof(value)); };
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) put(mesh.vertices[i][k]);
    if (normals) for (int k = 0; k < 3; ++k) put(mesh.normals[i][k]);
    if (colors)
      for (int k = 0; k < 3; ++k) {
        const float c = mesh.colors[i][k];
        put(static_cast<uint8_t>(c > 0.0f ? (c >= 1.0f ? 255 : std::lround(c * 255.0f)) : 0));
      }
    if (planes) put(static_cast<int32_t>(mesh.plane_ids[i]));
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    put(uint8_t{3});
    for (int k = 0; k < 3; ++k) put(static_cast<int32_t>(t[k]));
  }
  write_atomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot create " + tmp.string());
    out.write(header.data(), std::streamsize(header.size()));
    out.write(body.data(), std::streamsize(body.size()));
    out.close();
    if (!out) throw std::runtime_error("error writing PLY file " + path.string());
  });
}

}  // namespace rrg::io
