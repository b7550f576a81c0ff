// TriangleMesh <-> Draco through libdraco's Mesh: one Draco point per vertex (identity mapping),
// positions/normals as float32 (quantised by the encoder), colours as normalised uint8 RGB, plane
// ids as a GENERIC int32 attribute (integers are coded losslessly).
#include "core/io/draco_mesh.h"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace rrg::io {
namespace {

using draco::GeometryAttribute;

void check_options(const DracoOptions& o) {
  auto in = [](int v, int lo, int hi) { return v >= lo && v <= hi; };
  if (!in(o.position_bits, 1, 30))
    throw std::invalid_argument("draco: position_bits must be 1..30, got " + std::to_string(o.position_bits));
  if (!in(o.normal_bits, 1, 30))
    throw std::invalid_argument("draco: normal_bits must be 1..30, got " + std::to_string(o.normal_bits));
  if (o.color_bits != 8)
    throw std::invalid_argument("draco: colours are sent as uint8, color_bits must be 8, got " +
                                std::to_string(o.color_bits));
  if (!in(o.speed, 0, 10)) throw std::invalid_argument("draco: speed must be 0..10, got " + std::to_string(o.speed));
}

// Adds an attribute with one value per point (identity mapping) and returns it for filling.
draco::PointAttribute* add_attribute(draco::Mesh& m, GeometryAttribute::Type type, int components,
                                     draco::DataType data_type, bool normalized) {
  auto pa = std::make_unique<draco::PointAttribute>();
  pa->Init(type, int8_t(components), data_type, normalized, m.num_points());
  return m.attribute(m.AddAttribute(std::move(pa)));
}

uint8_t to_u8(float c) {
  if (!(c > 0.0f)) return 0;  // also NaN
  if (c >= 1.0f) return 255;
  return uint8_t(std::lround(c * 255.0f));
}

Eigen::Vector3f read_vec3(const draco::PointAttribute& a, draco::PointIndex p, const char* what) {
  float v[3] = {0, 0, 0};
  if (!a.ConvertValue<float>(a.mapped_index(p), 3, v))
    throw std::invalid_argument(std::string("draco: cannot read the ") + what + " of point " + std::to_string(p.value()));
  if (a.data_type() == draco::DT_UINT8 && !a.normalized())
    for (float& c : v) c /= 255.0f;  // non-normalised 8-bit colours from other encoders
  return {v[0], v[1], v[2]};
}

}  // namespace

std::vector<uint8_t> encode_draco(const TriangleMesh& mesh, const DracoOptions& options) {
  check_options(options);
  try {
    mesh.validate();
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(std::string("draco: invalid mesh: ") + e.what());
  }
  if (mesh.triangles.empty()) throw std::invalid_argument("draco: the mesh has no triangles");

  draco::Mesh m;
  const size_t nv = mesh.vertices.size();
  m.set_num_points(draco::PointIndex::ValueType(nv));
  draco::PointAttribute* pos = add_attribute(m, GeometryAttribute::POSITION, 3, draco::DT_FLOAT32, false);
  for (size_t i = 0; i < nv; ++i) pos->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), mesh.vertices[i].data());
  if (!mesh.normals.empty()) {
    draco::PointAttribute* nrm = add_attribute(m, GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32, false);
    for (size_t i = 0; i < nv; ++i) nrm->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), mesh.normals[i].data());
  }
  if (!mesh.colors.empty()) {
    draco::PointAttribute* col = add_attribute(m, GeometryAttribute::COLOR, 3, draco::DT_UINT8, true);
    for (size_t i = 0; i < nv; ++i) {
      const uint8_t rgb[3] = {to_u8(mesh.colors[i].x()), to_u8(mesh.colors[i].y()), to_u8(mesh.colors[i].z())};
      col->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), rgb);
    }
  }
  if (!mesh.plane_ids.empty()) {
    draco::PointAttribute* ids = add_attribute(m, GeometryAttribute::GENERIC, 1, draco::DT_INT32, false);
    for (size_t i = 0; i < nv; ++i) ids->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), &mesh.plane_ids[i]);
  }
  m.SetNumFaces(mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    m.SetFace(draco::FaceIndex(uint32_t(f)),
              {draco::PointIndex(uint32_t(t.x())), draco::PointIndex(uint32_t(t.y())), draco::PointIndex(uint32_t(t.z()))});
  }

  draco::Encoder enc;
  enc.SetSpeedOptions(options.speed, options.speed);
  // Edgebreaker drops faces with a repeated vertex; the sequential coder keeps every face, so the
  // decoded face count always equals ours (GetMesh promises the session's counts).
  const bool degenerate = std::any_of(mesh.triangles.begin(), mesh.triangles.end(), [](const Eigen::Vector3i& t) {
    return t.x() == t.y() || t.y() == t.z() || t.x() == t.z();
  });
  if (degenerate) enc.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  enc.SetAttributeQuantization(GeometryAttribute::POSITION, options.position_bits);
  enc.SetAttributeQuantization(GeometryAttribute::NORMAL, options.normal_bits);
  draco::EncoderBuffer buf;
  const draco::Status status = enc.EncodeMeshToBuffer(m, &buf);
  if (!status.ok()) throw std::runtime_error(std::string("draco: encoding failed: ") + status.error_msg());
  return {reinterpret_cast<const uint8_t*>(buf.data()), reinterpret_cast<const uint8_t*>(buf.data()) + buf.size()};
}

TriangleMesh decode_draco(std::span<const uint8_t> bytes) {
  if (bytes.empty()) throw std::invalid_argument("draco: empty buffer");
  draco::DecoderBuffer buf;
  buf.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  auto type = draco::Decoder::GetEncodedGeometryType(&buf);
  if (!type.ok()) throw std::invalid_argument(std::string("draco: not a Draco buffer: ") + type.status().error_msg());
  if (type.value() != draco::TRIANGULAR_MESH) throw std::invalid_argument("draco: the buffer holds a point cloud, not a mesh");
  draco::Decoder dec;
  auto decoded = dec.DecodeMeshFromBuffer(&buf);
  if (!decoded.ok()) throw std::invalid_argument(std::string("draco: corrupt mesh: ") + decoded.status().error_msg());
  const draco::Mesh& m = *decoded.value();

  const draco::PointAttribute* pos = m.GetNamedAttribute(GeometryAttribute::POSITION);
  if (!pos) throw std::invalid_argument("draco: the mesh has no positions");
  const draco::PointAttribute* nrm = m.GetNamedAttribute(GeometryAttribute::NORMAL);
  const draco::PointAttribute* col = m.GetNamedAttribute(GeometryAttribute::COLOR);
  const draco::PointAttribute* ids = m.GetNamedAttribute(GeometryAttribute::GENERIC);
  if (ids && (ids->num_components() != 1 || ids->data_type() != draco::DT_INT32)) ids = nullptr;  // not ours

  TriangleMesh out;
  const uint32_t n = m.num_points();
  out.vertices.resize(n);
  if (nrm) out.normals.resize(n);
  if (col) out.colors.resize(n);
  if (ids) out.plane_ids.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    const draco::PointIndex p(i);
    out.vertices[i] = read_vec3(*pos, p, "position");
    if (nrm) out.normals[i] = read_vec3(*nrm, p, "normal");
    if (col) out.colors[i] = read_vec3(*col, p, "colour");
    if (ids && !ids->ConvertValue<int32_t>(ids->mapped_index(p), 1, &out.plane_ids[i]))
      throw std::invalid_argument("draco: cannot read the plane id of point " + std::to_string(i));
  }
  out.triangles.resize(m.num_faces());
  for (uint32_t f = 0; f < m.num_faces(); ++f) {
    const auto& face = m.face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      if (face[k].value() >= n)
        throw std::invalid_argument("draco: face " + std::to_string(f) + " indexes point " +
                                    std::to_string(face[k].value()) + " of " + std::to_string(n));
      out.triangles[f][k] = int(face[k].value());
    }
  }
  return out;
}

}  // namespace rrg::io
