#include "core/common/parallel_for.h"
#include "core/tsdf/tsdf_storage_impl.h"

namespace rrg::kernel {

void touch_blocks_cpu(const TouchArgs& a) { touch_blocks(CpuBackend{}, a); }
void append_blocks_cpu(const AppendArgs& a) { append_blocks(CpuBackend{}, a); }
void clear_hash_cpu(HashView h) { clear_hash(CpuBackend{}, h); }
void insert_known_cpu(HashView h, Span<const uint64_t> keys, int32_t first, int32_t* failed) {
  insert_known(CpuBackend{}, h, keys, first, failed);
}
void gather_blocks_cpu(PoolView pool, Span<const int32_t> index, Span<Voxel> records) {
  gather_blocks(CpuBackend{}, pool, index, records);
}
void scatter_blocks_cpu(Span<const Voxel> records, Span<const int32_t> index, PoolView pool) {
  scatter_blocks(CpuBackend{}, records, index, pool);
}
void update_crossing_boxes_cpu(Span<const TsdfVoxel> geometry, Span<const int32_t> blocks, Span<uint32_t> boxes) {
  update_crossing_boxes(CpuBackend{}, geometry, blocks, boxes);
}

}  // namespace rrg::kernel
