#include "core/tsdf/tsdf_mesh.h"

#include "core/common/dispatch.h"
#include "core/tsdf/tsdf_mesh_impl.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <tuple>
#include <unordered_map>

namespace rrg {
namespace {

constexpr int64_t kBatchBlocks = 8192;  // scratch: 8192 blocks × 2187 edges × 4 B = 72 MB

struct EdgeKeyHash {
  size_t operator()(const Eigen::Vector4i& k) const {
    uint64_t h = 14695981039346656037ull;
    for (int i = 0; i < 4; ++i) h = (h ^ uint32_t(k[i])) * 1099511628211ull;
    return size_t(h);
  }
};
struct EdgeKeyEq {
  bool operator()(const Eigen::Vector4i& a, const Eigen::Vector4i& b) const { return a == b; }
};

// Merges the vertices that several blocks emitted for one edge: those on a block face, i.e. with a
// coordinate other than the edge's axis that is a multiple of 8.
void weld(TriangleMesh& mesh, const std::vector<Eigen::Vector4i>& keys) {
  std::unordered_map<Eigen::Vector4i, int32_t, EdgeKeyHash, EdgeKeyEq> first;
  std::vector<int32_t> index(mesh.vertices.size());
  TriangleMesh out;
  out.vertices.reserve(mesh.vertices.size());
  out.colors.reserve(mesh.vertices.size());
  out.plane_ids.reserve(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector4i& k = keys[i];
    bool border = false;
    for (int c = 0; c < 3; ++c) border |= c != k[3] && (k[c] & 7) == 0;
    if (border) {
      const auto [it, fresh] = first.emplace(k, int32_t(out.vertices.size()));
      if (!fresh) {
        index[i] = it->second;
        continue;
      }
    }
    index[i] = int32_t(out.vertices.size());
    out.vertices.push_back(mesh.vertices[i]);
    out.colors.push_back(mesh.colors[i]);
    out.plane_ids.push_back(mesh.plane_ids[i]);
  }
  out.triangles = std::move(mesh.triangles);
  for (auto& t : out.triangles) t = Eigen::Vector3i(index[size_t(t.x())], index[size_t(t.y())], index[size_t(t.z())]);
  mesh = std::move(out);
}

TriangleMesh mesh_pool_blocks(const TsdfVolume& volume, const std::vector<int32_t>& blocks,
                              std::span<const int32_t> plane_remap) {
  const Device& dev = volume.device();
  const auto& table_host = mc::triangle_table();
  const auto table = Buffer<int8_t>::from_host(table_host, dev);
  const auto remap = Buffer<int32_t>::from_host(plane_remap, dev);
  TriangleMesh mesh;
  std::vector<Eigen::Vector4i> keys;
  for (size_t start = 0; start < blocks.size(); start += size_t(kBatchBlocks)) {
    const size_t m = std::min(blocks.size() - start, size_t(kBatchBlocks));
    const auto blocks_d = Buffer<int32_t>::from_host(std::span(blocks).subspan(start, m), dev);
    Buffer<int32_t> scratch(m * kernel::kEdgeSlots, dev), counts(2 * m, dev);
    kernel::MeshArgs a{{volume.hash_view(), volume.geometry(), volume.attributes(), volume.params().voxel_size},
                       volume.block_keys(), blocks_d.span(), table.span(), remap.span(), scratch.span(),
                       false, counts.span(), {}, {}, {}, {}, {}, {}};
    RRG_DISPATCH(dev, kernel::mesh_blocks_cpu(a), kernel::mesh_blocks_cuda(a));
    const std::vector<int32_t> c = counts.to_host();
    std::vector<int64_t> offsets(2 * m);  // batch-local first vertex / triangle of each block
    const int64_t base = int64_t(mesh.vertices.size());
    int64_t nv = 0, nt = 0;
    for (size_t j = 0; j < m; ++j) {
      offsets[2 * j] = nv;
      offsets[2 * j + 1] = nt;
      nv += c[2 * j];
      nt += c[2 * j + 1];
    }
    if (nt == 0) continue;
    const auto offsets_d = Buffer<int64_t>::from_host(offsets, dev);
    Buffer<Eigen::Vector3f> pos(size_t(nv), dev), col(size_t(nv), dev);
    Buffer<int32_t> planes(size_t(nv), dev);
    Buffer<Eigen::Vector4i> edge_keys(size_t(nv), dev);
    Buffer<Eigen::Vector3i> tris(size_t(nt), dev);
    a.emit = true;
    a.offsets = offsets_d.span();
    a.positions = pos.span();
    a.colors = col.span();
    a.planes = planes.span();
    a.edge_keys = edge_keys.span();
    a.triangles = tris.span();
    RRG_DISPATCH(dev, kernel::mesh_blocks_cpu(a), kernel::mesh_blocks_cuda(a));
    const auto p = pos.to_host(), cl = col.to_host();
    const auto pl = planes.to_host();
    const auto ek = edge_keys.to_host();
    auto tr = tris.to_host();
    for (auto& t : tr) t += Eigen::Vector3i::Constant(int(base));
    mesh.vertices.insert(mesh.vertices.end(), p.begin(), p.end());
    mesh.colors.insert(mesh.colors.end(), cl.begin(), cl.end());
    mesh.plane_ids.insert(mesh.plane_ids.end(), pl.begin(), pl.end());
    keys.insert(keys.end(), ek.begin(), ek.end());
    mesh.triangles.insert(mesh.triangles.end(), tr.begin(), tr.end());
  }
  weld(mesh, keys);
  return mesh;
}

// Orders pool slots by their block's coordinates (x, then y, then z), so the mesh's vertex and
// triangle order depends on the map only, not on the order its blocks were allocated (a map
// restored from a snapshot then meshes to the same bytes).
void sort_by_coords(std::vector<int32_t>& blocks, const std::vector<Eigen::Vector3i>& coords) {
  std::sort(blocks.begin(), blocks.end(), [&](int32_t a, int32_t b) {
    const Eigen::Vector3i& ca = coords[size_t(a)];
    const Eigen::Vector3i& cb = coords[size_t(b)];
    return std::tie(ca.x(), ca.y(), ca.z()) < std::tie(cb.x(), cb.y(), cb.z());
  });
}

}  // namespace

TriangleMesh extract_mesh(const TsdfVolume& volume, std::span<const int32_t> plane_remap) {
  if (volume.num_host_blocks() > 0)
    spdlog::warn("extract_mesh: {} blocks are streamed out to host memory and not meshed "
                 "(stream_in_all() first to mesh everything)", volume.num_host_blocks());
  std::vector<int32_t> blocks(size_t(volume.num_blocks()));
  for (size_t i = 0; i < blocks.size(); ++i) blocks[i] = int32_t(i);
  sort_by_coords(blocks, volume.block_coords());
  return mesh_pool_blocks(volume, blocks, plane_remap);
}

TriangleMesh extract_mesh(const TsdfVolume& volume, std::span<const Eigen::Vector3i> coords,
                          std::span<const int32_t> plane_remap) {
  const std::vector<Eigen::Vector3i> all = volume.block_coords();
  std::unordered_map<uint64_t, int32_t> index;
  for (size_t i = 0; i < all.size(); ++i) index[block_key(all[i].x(), all[i].y(), all[i].z())] = int32_t(i);
  std::vector<int32_t> blocks;
  for (const auto& c : coords)
    if (auto it = index.find(block_key(c.x(), c.y(), c.z())); it != index.end()) blocks.push_back(it->second);
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  sort_by_coords(blocks, all);
  return mesh_pool_blocks(volume, blocks, plane_remap);
}

}  // namespace rrg
