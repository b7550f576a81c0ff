#include "core/tsdf/tsdf_mesh.h"

#include "core/common/dispatch.h"
#include "core/tsdf/tsdf_mesh_impl.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

namespace rrg {
namespace {

// Blocks per kernel launch. The per-block edge scratch (2187 × 4 B) is allocated once and reused,
// so its pages are touched once per call: on the CPU a batch of 1024 blocks (9 MB) stays warm; on
// the GPU 8192 blocks (72 MB) keep the device busy.
int64_t batch_blocks(const Device& dev) { return dev.is_cuda() ? 8192 : 1024; }

// Merges the vertices that several blocks emitted for one edge: those on a block face, i.e. with a
// coordinate other than the edge's axis that is a multiple of 8. The first vertex of an edge stays
// (in emission order), the others are dropped and their triangles point to it; compacted in place
// with an open-addressing table of the border edges seen.
void weld(TriangleMesh& mesh, const std::vector<Eigen::Vector4i>& keys) {
  const size_t n = mesh.vertices.size();
  size_t border_count = 0;
  const auto on_border = [](const Eigen::Vector4i& k) {
    bool border = false;
    for (int c = 0; c < 3; ++c) border |= c != k[3] && (k[c] & 7) == 0;
    return border;
  };
  for (size_t i = 0; i < n; ++i) border_count += on_border(keys[i]);
  size_t capacity = 16;
  while (capacity < 2 * border_count) capacity <<= 1;
  std::vector<int32_t> table(capacity, -1);  // vertex (input index) holding an edge, -1 = free
  const auto hash = [](const Eigen::Vector4i& k) {
    uint64_t h = 14695981039346656037ull;
    for (int i = 0; i < 4; ++i) h = (h ^ uint32_t(k[i])) * 1099511628211ull;
    return h ^ (h >> 29);
  };
  std::vector<int32_t> index(n);
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector4i& k = keys[i];
    if (on_border(k)) {
      size_t slot = size_t(hash(k)) & (capacity - 1);
      while (table[slot] >= 0 && keys[size_t(table[slot])] != k) slot = (slot + 1) & (capacity - 1);
      if (table[slot] >= 0) {
        index[i] = index[size_t(table[slot])];
        continue;
      }
      table[slot] = int32_t(i);
    }
    index[i] = int32_t(kept);
    mesh.vertices[kept] = mesh.vertices[i];
    mesh.colors[kept] = mesh.colors[i];
    mesh.plane_ids[kept] = mesh.plane_ids[i];
    ++kept;
  }
  mesh.vertices.resize(kept);
  mesh.colors.resize(kept);
  mesh.plane_ids.resize(kept);
  for (auto& t : mesh.triangles) t = Eigen::Vector3i(index[size_t(t.x())], index[size_t(t.y())], index[size_t(t.z())]);
}

// Appends the device array's n elements to a host vector, copied once.
template <class T>
void append_from(std::vector<T>& out, const Buffer<T>& b, const Device& dev) {
  const size_t at = out.size();
  out.resize(at + b.size());
  if (!b.empty()) mem::copy(out.data() + at, Device::cpu(), b.data(), dev, b.size() * sizeof(T));
}

// Appends the unwelded triangles of the resident pool slots `blocks` (in that order) to mesh, and
// each new vertex's edge key to keys.
void emit_pool_blocks(const TsdfVolume& volume, const std::vector<int32_t>& blocks, std::span<const int32_t> plane_remap,
                      TriangleMesh& mesh, std::vector<Eigen::Vector4i>& keys) {
  if (blocks.empty()) return;
  const Device& dev = volume.device();
  const auto& table_host = mc::triangle_table();
  const auto table = Buffer<int8_t>::from_host(table_host, dev);
  const auto remap = Buffer<int32_t>::from_host(plane_remap, dev);
  const size_t batch = std::min(blocks.size(), size_t(batch_blocks(dev)));
  Buffer<int32_t> scratch(batch * kernel::kEdgeSlots, dev), counts(2 * batch, dev);
  for (size_t start = 0; start < blocks.size(); start += batch) {
    const size_t m = std::min(blocks.size() - start, batch);
    const auto blocks_d = Buffer<int32_t>::from_host(std::span(blocks).subspan(start, m), dev);
    kernel::MeshArgs a{{volume.hash_view(), volume.geometry(), volume.attributes(), volume.params().voxel_size},
                       volume.block_keys(), blocks_d.span(), table.span(), remap.span(), scratch.span(),
                       false, counts.span(), {}, 0, {}, {}, {}, {}, {}};
    RRG_DISPATCH(dev, kernel::mesh_blocks_cpu(a), kernel::mesh_blocks_cuda(a));
    const std::vector<int32_t> c = download_prefix(counts, int64_t(2 * m));  // vertices, triangles per block
    std::vector<int64_t> offsets(2 * m);  // batch-local first vertex / triangle of each block
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
    a.vertex_base = int64_t(mesh.vertices.size());
    a.positions = pos.span();
    a.colors = col.span();
    a.planes = planes.span();
    a.edge_keys = edge_keys.span();
    a.triangles = tris.span();
    RRG_DISPATCH(dev, kernel::mesh_blocks_cpu(a), kernel::mesh_blocks_cuda(a));
    append_from(mesh.vertices, pos, dev);
    append_from(mesh.colors, col, dev);
    append_from(mesh.plane_ids, planes, dev);
    append_from(keys, edge_keys, dev);
    append_from(mesh.triangles, tris, dev);
  }
}

TriangleMesh mesh_pool_blocks(const TsdfVolume& volume, const std::vector<int32_t>& blocks,
                              std::span<const int32_t> plane_remap) {
  TriangleMesh mesh;
  std::vector<Eigen::Vector4i> keys;
  emit_pool_blocks(volume, blocks, plane_remap, mesh, keys);
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
                 "(extract_mesh_streamed() meshes everything)", volume.num_host_blocks());
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

TriangleMesh extract_mesh_streamed(TsdfVolume& volume, int64_t max_resident_blocks,
                                   std::span<const int32_t> plane_remap) {
  if (volume.num_host_blocks() == 0) return extract_mesh(volume, plane_remap);
  if (max_resident_blocks < 1)
    throw std::invalid_argument("extract_mesh_streamed: max_resident_blocks must be >= 1, got " +
                                std::to_string(max_resident_blocks));
  const auto key_of = [](const Eigen::Vector3i& c) { return block_key(c.x(), c.y(), c.z()); };
  const std::vector<Eigen::Vector3i> resident = volume.block_coords();
  std::vector<Eigen::Vector3i> all = volume.host_block_coords();
  all.insert(all.end(), resident.begin(), resident.end());
  std::sort(all.begin(), all.end(), [&](const auto& a, const auto& b) { return key_of(a) < key_of(b); });
  // Block keys order by x first, so a slab of consecutive x is a run of `all`, and meshing the slabs
  // in turn emits the blocks in the order of extract_mesh: one weld at the end gives its bytes.
  const auto layer_end = [&](size_t i) {
    size_t e = i;
    while (e < all.size() && all[e].x() == all[i].x()) ++e;
    return e;
  };
  // Marching cubes reads the +x neighbour layer too (the cubes on a block's +x face).
  const auto margin = [&](size_t end) {
    return end < all.size() && all[end].x() == all[end - 1].x() + 1 ? layer_end(end) - end : size_t{0};
  };
  volume.stream_out(resident);
  TriangleMesh mesh;
  std::vector<Eigen::Vector4i> keys;
  const size_t budget = size_t(max_resident_blocks);
  size_t slabs = 0, peak = 0;
  for (size_t begin = 0; begin < all.size();) {
    size_t end = layer_end(begin);
    while (end < all.size() && layer_end(end) - begin + margin(layer_end(end)) <= budget) end = layer_end(end);
    const size_t with_margin = end + margin(end);
    // Out goes what lies before this slab; the previous slab's margin layer is this slab's first.
    std::vector<Eigen::Vector3i> before;
    for (const Eigen::Vector3i& c : volume.block_coords())
      if (c.x() < all[begin].x()) before.push_back(c);
    volume.stream_out(before);
    volume.stream_in(std::span(all).subspan(begin, with_margin - begin));
    peak = std::max(peak, size_t(volume.num_blocks()));
    const std::vector<Eigen::Vector3i> pool = volume.block_coords();
    std::unordered_map<uint64_t, int32_t> slot;
    for (size_t i = 0; i < pool.size(); ++i) slot[key_of(pool[i])] = int32_t(i);
    std::vector<int32_t> blocks;
    blocks.reserve(end - begin);
    for (size_t i = begin; i < end; ++i) blocks.push_back(slot.at(key_of(all[i])));
    emit_pool_blocks(volume, blocks, plane_remap, mesh, keys);
    ++slabs;
    begin = end;
  }
  volume.stream_out(volume.block_coords());
  volume.stream_in(resident);
  spdlog::debug("extract_mesh_streamed: {} blocks in {} slabs, at most {} resident (budget {})", all.size(), slabs,
                peak, budget);
  weld(mesh, keys);
  return mesh;
}

}  // namespace rrg
