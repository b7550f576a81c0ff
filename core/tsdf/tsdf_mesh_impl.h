#pragma once
// The body of extract_mesh() (tsdf_mesh.h): one thread per block walks its 8³ cubes in a fixed
// order (so the output order is the same on every back end), first counting vertices and
// triangles, then (after a scan on the host) writing them. Instantiated by tsdf_mesh_cpu.cpp and
// tsdf_mesh_cuda.cu.
#include "core/tsdf/marching_cubes_table.h"
#include "core/tsdf/tsdf_integrate_device.h"
#include "core/tsdf/tsdf_sample_device.h"

namespace rrg::kernel {

inline constexpr int kExt = kBlockSide + 1;                 // a block's cubes touch 9³ voxels
inline constexpr int kEdgeSlots = kExt * kExt * kExt * 3;   // edges per block (scratch)

struct MeshArgs {
  VolumeView volume;
  Span<const uint64_t> block_keys;     // pool
  Span<const int32_t> blocks;          // [m] pool indices to mesh
  Span<const int8_t> table;            // mc::triangle_table()
  Span<const int32_t> remap;
  Span<int32_t> scratch;               // [m * kEdgeSlots]
  bool emit;
  Span<int32_t> counts;                // [2m] vertices, triangles (count pass)
  Span<const int64_t> offsets;         // [2m] first vertex, first triangle (emit pass)
  int64_t vertex_base = 0;             // added to the vertex indices written into `triangles`
  Span<Eigen::Vector3f> positions, colors;
  Span<int32_t> planes;
  Span<Eigen::Vector4i> edge_keys;     // global lower voxel and axis of each vertex (welding)
  Span<Eigen::Vector3i> triangles;
};

template <class Backend>
void mesh_blocks(Backend backend, const MeshArgs& a) {
  const MeshArgs args = a;
  parallel_for(backend, a.blocks.size, [=] RRG_HD(int64_t j) {
    const Eigen::Vector3i bc = block_coord(args.block_keys[args.blocks[j]]);
    int32_t nb[8];
    for (int o = 0; o < 8; ++o) {
      const Eigen::Vector3i c = bc + Eigen::Vector3i(o & 1, (o >> 1) & 1, o >> 2);
      nb[o] = block_in_range(c.x(), c.y(), c.z()) ? hash_find(args.volume.hash, block_key(c.x(), c.y(), c.z())) : -1;
    }
    // Pool index of the voxel at local coordinates l (0..8), or -1 when missing or unobserved.
    const auto fetch = [&](const Eigen::Vector3i& l) -> int64_t {
      const int o = (l.x() >> 3) | ((l.y() >> 3) << 1) | ((l.z() >> 3) << 2);
      if (nb[o] < 0) return -1;
      const int64_t v = int64_t(nb[o]) * kBlockVoxels + local_index(l.x() & 7, l.y() & 7, l.z() & 7);
      return args.volume.geometry[v].weight > 0 ? v : -1;
    };
    int32_t* slots = &args.scratch[j * kEdgeSlots];
    for (int k = 0; k < kEdgeSlots; ++k) slots[k] = -1;
    const int64_t v0 = args.emit ? args.offsets[2 * j] : 0, t0 = args.emit ? args.offsets[2 * j + 1] : 0;
    const float s = args.volume.voxel_size;
    int32_t nv = 0, nt = 0;
    for (int z = 0; z < kBlockSide; ++z)
      for (int y = 0; y < kBlockSide; ++y)
        for (int x = 0; x < kBlockSide; ++x) {
          int m = 0;
          bool ok = true;
          for (int c = 0; c < 8 && ok; ++c) {
            const int64_t v = fetch(Eigen::Vector3i(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2)));
            if (v < 0) ok = false;
            else if (args.volume.geometry[v].tsdf < 0) m |= 1 << c;
          }
          if (!ok || m == 0 || m == 255) continue;
          const int8_t* tri = &args.table[int64_t(m) * mc::kStride];
          for (int k = 0; tri[k] >= 0; k += 3) {
            int32_t idx[3];
            for (int q = 0; q < 3; ++q) {
              const int e = tri[k + q], axis = mc::edge_axis(e);
              const Eigen::Vector3i la = Eigen::Vector3i(x, y, z) + mc::edge_origin(e);
              const int slot = ((la.z() * kExt + la.y()) * kExt + la.x()) * 3 + axis;
              if (slots[slot] < 0) {
                slots[slot] = nv++;
                if (args.emit) {
                  Eigen::Vector3i lb = la;
                  lb[axis] += 1;
                  const int64_t ia = fetch(la), ib = fetch(lb);
                  const AttrVoxel& va = args.volume.attributes[ia];
                  const AttrVoxel& vb = args.volume.attributes[ib];
                  const float fa = voxel_codec::decode_tsdf(args.volume.geometry[ia].tsdf);
                  const float fb = voxel_codec::decode_tsdf(args.volume.geometry[ib].tsdf);
                  const float u = fa / (fa - fb);
                  const Eigen::Vector3i g = bc * int(kBlockSide) + la;
                  Eigen::Vector3f p = g.cast<float>();
                  p[axis] += u;
                  const int64_t out = v0 + slots[slot];
                  args.positions[out] = p * s;
                  args.colors[out] = voxel_color(va) + u * (voxel_color(vb) - voxel_color(va));
                  const AttrVoxel& near = (fabsf(fa) <= fabsf(fb) && va.plane) || !vb.plane ? va : vb;
                  args.planes[out] = canonical_plane(args.remap, int32_t(near.plane));
                  args.edge_keys[out] = Eigen::Vector4i(g.x(), g.y(), g.z(), axis);
                }
              }
              idx[q] = slots[slot];
            }
            if (args.emit)
              {
              const int64_t b = args.vertex_base + v0;
              args.triangles[t0 + nt] = Eigen::Vector3i(int(b + idx[0]), int(b + idx[1]), int(b + idx[2]));
            }
            ++nt;
          }
        }
    if (!args.emit) {
      args.counts[2 * j] = nv;
      args.counts[2 * j + 1] = nt;
    }
  });
}

void mesh_blocks_cpu(const MeshArgs& a);
void mesh_blocks_cuda(const MeshArgs& a);

}  // namespace rrg::kernel
