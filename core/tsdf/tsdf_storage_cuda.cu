#include "core/common/parallel_for_cuda.cuh"
#include "core/tsdf/tsdf_storage_impl.h"

namespace rrg::kernel {

void touch_blocks_cuda(const TouchArgs& a) {
  touch_blocks(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}
void append_blocks_cuda(const AppendArgs& a) {
  append_blocks(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}
void clear_hash_cuda(HashView h) {
  clear_hash(CudaBackend{}, h);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}
void insert_known_cuda(HashView h, Span<const uint64_t> keys, int32_t first, int32_t* failed) {
  insert_known(CudaBackend{}, h, keys, first, failed);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}
void gather_blocks_cuda(PoolView pool, Span<const int32_t> index, Span<Voxel> records) {
  gather_blocks(CudaBackend{}, pool, index, records);
}
void scatter_blocks_cuda(Span<const Voxel> records, Span<const int32_t> index, PoolView pool) {
  scatter_blocks(CudaBackend{}, records, index, pool);
}
void update_crossing_boxes_cuda(Span<const TsdfVoxel> geometry, Span<const int32_t> blocks, Span<uint32_t> boxes) {
  update_crossing_boxes(CudaBackend{}, geometry, blocks, boxes);
}

}  // namespace rrg::kernel
