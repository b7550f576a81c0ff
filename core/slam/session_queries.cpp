// Thread-safe queries of a session: renders of any camera, meshes, Gaussians, trajectory, status.
#include "core/slam/session_impl.h"
#include "core/tsdf/tsdf_mesh.h"

#include <algorithm>
#include <stdexcept>

namespace rrg {

SessionView Session::render(const Intrinsics& K, const Eigen::Isometry3f& T_wc) const {
  if (!K.valid() || K.width > 8192 || K.height > 8192)
    throw std::invalid_argument("render: bad intrinsics " + K.to_string());
  const Impl& s = *impl_;
  const RaycastResult rc = s.locked_raycast(K, T_wc, RaycastOutputs::all(), Impl::Reader::Client);  // pass 1
  RenderOutputs out;
  s.mapper.render(RenderCamera{K, T_wc}, rc, out);     // passes 2 and 3 on the published snapshot
  SessionView v;
  v.C = out.C.to_host();
  v.C_b = out.C_b.to_host();
  v.C_r = out.C_r.to_host();
  v.depth = out.D_b.to_host();
  v.R = rc.reflection_mask.to_host();
  v.RC_r = ColorImage(K.width, K.height, Color::Zero());
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x)
      if (v.R(x, y)) v.RC_r(x, y) = v.C_r(x, y);
  return v;
}

TriangleMesh Session::mesh(uint64_t changed_since) const {
  const Impl& s = *impl_;
  const std::vector<int32_t> remap = s.remap_copy();
  if (changed_since == 0) {
    {
      std::shared_lock lock(s.volume_mutex);
      if (s.volume.num_host_blocks() == 0) return extract_mesh(s.volume, remap);
    }
    // Streamed out (tsdf.stream_radius): meshed slab by slab with no more blocks resident than
    // now, the same mesh as with every block resident; the resident ones stay so.
    std::unique_lock lock(s.volume_mutex);
    const int64_t pool = s.volume.pool_capacity();
    TriangleMesh mesh = extract_mesh_streamed(s.volume, std::max<int64_t>(s.volume.num_blocks(), 1), remap);
    s.volume.shrink_pool(pool);
    return mesh;
  }
  std::vector<Eigen::Vector3i> blocks;
  {
    std::shared_lock lock(s.volume_mutex);
    blocks = s.volume.changed_blocks(changed_since);
  }
  return mesh_of_blocks(blocks);
}

Session::ChangedBlocks Session::changed_blocks(uint64_t since) const {
  const Impl& s = *impl_;
  std::shared_lock lock(s.volume_mutex);
  return {s.volume.changed_blocks(since), s.volume.version()};
}

TriangleMesh Session::mesh_of_blocks(const std::vector<Eigen::Vector3i>& blocks) const {
  const Impl& s = *impl_;
  const std::vector<int32_t> remap = s.remap_copy();
  return s.read_blocks(blocks, [&] { return extract_mesh(s.volume, blocks, remap); }, Impl::Reader::Client);
}

GaussianHost Session::base_gaussians() const { return impl_->mapper.base_host(); }
GaussianHost Session::reflection_gaussians() const { return impl_->mapper.reflection_host(); }

std::vector<ReflectivePlane> Session::reflective_planes() const {
  std::lock_guard lock(impl_->state_mutex);
  return impl_->reflective;
}

io::Trajectory Session::trajectory() const {
  std::lock_guard lock(impl_->state_mutex);
  return impl_->trajectory;
}

std::vector<FrameReport> Session::reports() const {
  std::lock_guard lock(impl_->state_mutex);
  return impl_->reports;
}

SessionStatus Session::status() const {
  const Impl& s = *impl_;
  SessionStatus st;
  {
    std::shared_lock lock(s.volume_mutex);
    st.tsdf_blocks = s.volume.num_blocks() + s.volume.num_host_blocks();
    st.resident_blocks = s.volume.num_blocks();
    const MemoryUsage m = s.volume.memory();
    st.device_bytes = m.device_bytes;
    st.tsdf_device_bytes = m.device_bytes;
    st.host_bytes = m.host_bytes;
  }
  std::lock_guard lock(s.state_mutex);
  st.frames = int64_t(s.reports.size());
  for (const FrameReport& r : s.reports) {
    st.fused += r.fused ? 1 : 0;
    st.lost += r.state == TrackingState::Lost ? 1 : 0;
  }
  if (!s.reports.empty()) {
    st.last_index = s.reports.back().index;
    st.T_wc = s.reports.back().T_wc;
    st.state = s.reports.back().state;
  }
  st.map_version = s.map_version.load();
  st.keyframes = int64_t(s.tracker_keyframes);
  st.global_planes = int64_t(s.global_planes);
  for (const ReflectivePlane& p : s.reflective) st.reflective_planes.push_back(p.id);
  st.mapping = s.mapping;
  // device memory of the Gaussians (parameters, gradients and two Adam moments: ~4x the 59 floats
  // of a degree-3 Gaussian), an estimate for admission control
  const size_t gaussian_bytes = size_t(s.mapping.base_gaussians + s.mapping.reflection_gaussians) * 4 * 59 * sizeof(float);
  st.device_bytes += gaussian_bytes;
  return st;
}

}  // namespace rrg
