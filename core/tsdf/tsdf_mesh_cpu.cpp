#include "core/common/parallel_for.h"
#include "core/tsdf/tsdf_mesh_impl.h"

namespace rrg::kernel {

void mesh_blocks_cpu(const MeshArgs& a) { mesh_blocks(CpuBackend{}, a); }

}  // namespace rrg::kernel
