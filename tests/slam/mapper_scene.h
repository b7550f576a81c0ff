#pragma once
// Test-only driver for the mapper tests and the mapping bench: a synthetic preset rendered at
// ground-truth poses (training frames + held-out novel views), a TSDF fused from the training frames
// with the ground-truth plane ids and a reflection mask of the chosen reflective planes, and the
// MappingContext the session would give the mapper (raycast of that TSDF + the planes' equations).
#include "core/slam/mapper.h"
#include "core/synth/renderer.h"
#include "core/tsdf/tsdf_volume.h"

#include <memory>
#include <string>
#include <vector>

namespace rrg::test {

struct MapperSceneParams {
  std::string preset = "mirror_room";
  int width = 64, height = 48;
  int frames = 20;            // training frames (every `stride`-th of a 30 fps loop)
  int stride = 3;
  int novel = 0;              // held-out views
  float voxel = 0.02f;        // TSDF voxel size, metres
  bool mirror_only = true;    // reflective planes = the mirror category only (else every F0 > 0 plane)
  int away = 0;               // further training frames: the first `away` poses turned 180° about the camera's y axis
};

struct MapperScene {
  Intrinsics K;
  std::vector<Eigen::Isometry3f> poses, novel_poses;
  std::vector<synth::RenderOutput> frames, novel;
  std::unique_ptr<TsdfVolume> volume;
  std::vector<ReflectivePlane> planes;  // reflective planes (equations from the scene)

  MappingContext context() const;
  MappingFrame frame(size_t i) const;
  // 1 where a view's first hit lies on one of `planes` (the reflective pixels).
  MaskImage reflective_pixels(const synth::RenderOutput& view) const;
};

MapperScene make_mapper_scene(const MapperSceneParams& params);

}  // namespace rrg::test
