#include "tests/slam/mapper_scene.h"

#include "core/synth/sequence.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_raycast.h"

#include <algorithm>

namespace rrg::test {

MappingContext MapperScene::context() const {
  MappingContext ctx;
  const TsdfVolume* v = volume.get();
  ctx.raycast = [v](const Intrinsics& K, const Eigen::Isometry3f& T_wc) { return raycast(*v, K, T_wc); };
  ctx.planes = planes;
  return ctx;
}

MappingFrame MapperScene::frame(size_t i) const {
  return MappingFrame{int64_t(i), poses[i], frames[i].color, frames[i].depth};
}

MaskImage MapperScene::reflective_pixels(const synth::RenderOutput& view) const {
  MaskImage m(view.planes.width(), view.planes.height(), 0);
  for (size_t i = 0; i < m.size(); ++i)
    for (const ReflectivePlane& p : planes)
      if (int32_t(view.planes[i]) == p.id) m[i] = 1;
  return m;
}

MapperScene make_mapper_scene(const MapperSceneParams& p) {
  const synth::SceneSpec spec = synth::make_preset(p.preset, 0);
  const synth::CameraPath path = synth::make_camera_path(spec);
  synth::SynthParams sp;
  sp.preset = p.preset;
  sp.width = p.width;
  sp.height = p.height;
  sp.frames = p.frames * p.stride;
  sp.novel = std::max(p.novel, 1);
  const synth::SequencePlan plan = synth::plan_sequence(spec, path, sp);
  MapperScene s;
  s.K = plan.K;
  for (const auto& pl : spec.scene.planes())
    if (pl.reflective && (!p.mirror_only || pl.category == synth::Category::Mirror))
      s.planes.push_back({int32_t(pl.id), Eigen::Vector4f(pl.normal.x(), pl.normal.y(), pl.normal.z(), pl.offset)});
  for (int i = 0; i < p.frames; ++i) {
    s.poses.push_back(plan.frames[size_t(i * p.stride)].T_wc.cast<float>());
    s.frames.push_back(synth::render_view(spec.scene, s.K, s.poses.back()));
  }
  for (int i = 0; i < p.away; ++i) {
    const Eigen::Isometry3f T = s.poses[size_t(i)] * Eigen::AngleAxisf(3.14159265f, Eigen::Vector3f::UnitY());
    s.poses.push_back(T);
    s.frames.push_back(synth::render_view(spec.scene, s.K, T));
  }
  for (int i = 0; i < p.novel; ++i) {
    s.novel_poses.push_back(plan.novel[size_t(i)].T_wc.cast<float>());
    s.novel.push_back(synth::render_view(spec.scene, s.K, s.novel_poses.back()));
  }
  TsdfParams tp;
  tp.voxel_size = p.voxel;
  tp.truncation = std::max(0.02f, 2.0f * p.voxel);
  s.volume = std::make_unique<TsdfVolume>(tp, Device::cpu());
  for (size_t i = 0; i < s.frames.size(); ++i) {
    const synth::RenderOutput& f = s.frames[i];
    Image<int32_t> ids(f.planes.width(), f.planes.height());
    for (size_t k = 0; k < ids.size(); ++k) ids[k] = int32_t(f.planes[k]);
    const MaskImage mask = s.reflective_pixels(f);
    const auto d_ids = DeviceImage<int32_t>::from_host(ids, Device::cpu());
    const auto d_mask = DeviceImage<uint8_t>::from_host(mask, Device::cpu());
    const ReflectionObservation obs{&d_ids, &d_mask, {}};
    integrate(*s.volume, DeviceImage<float>::from_host(f.depth, Device::cpu()),
              DeviceImage<Color>::from_host(f.color, Device::cpu()), s.K, s.poses[i], &obs);
  }
  return s;
}

}  // namespace rrg::test
