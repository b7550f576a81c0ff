// TsdfModelSource: ICP's model raycast, and the plane-id map it keeps for the tracking mask's warp
// (set_plane_ids), canonical through the remap table.
#include "core/tracking/model_source.h"
#include "core/tsdf/tsdf_integrate.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace rrg {
namespace {

TEST(TsdfModelSource, KeepsThePlaneIdsThroughTheRemapWhenAskedFor) {
  const Intrinsics K{60.0f, 60.0f, 31.5f, 23.5f, 64, 48};
  TsdfParams p;
  p.voxel_size = 0.02f;
  p.truncation = 0.08f;
  TsdfVolume volume(p, Device::cpu());
  // A wall 1 m in front of the camera, fused with plane id 3 on every pixel.
  const auto depth = DeviceImage<float>::from_host(DepthImage(K.width, K.height, 1.0f), Device::cpu());
  const auto color = DeviceImage<Color>::from_host(ColorImage(K.width, K.height, Color(0.5f, 0.5f, 0.5f)), Device::cpu());
  const auto ids = DeviceImage<int32_t>::from_host(Image<int32_t>(K.width, K.height, 3), Device::cpu());
  const auto mask = DeviceImage<uint8_t>::from_host(MaskImage(K.width, K.height, 0), Device::cpu());
  const ReflectionObservation obs{&ids, &mask, {}};
  const Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  integrate(volume, depth, color, K, T, &obs);

  TsdfModelSource model(volume, K);
  EXPECT_EQ(model.last(), nullptr);
  model.model_at(T);
  ASSERT_NE(model.last(), nullptr);
  EXPECT_EQ(model.last()->plane_ids.width(), 0) << "geometry only by default";

  const std::vector<int32_t> remap = {0, 1, 2, 1};  // 3 was merged into 1
  model.set_plane_ids(true, remap);
  EXPECT_EQ(model.last(), nullptr) << "a change forgets the cached raycast";
  model.model_at(T);
  const Image<int32_t> I = model.last()->plane_ids.to_host();
  const DepthImage D = model.last()->depth.to_host();
  int64_t hits = 0;
  for (size_t i = 0; i < I.size(); ++i)
    if (D[i] > 0) {
      ++hits;
      EXPECT_EQ(I[i], 1) << "pixel " << i;
    }
  EXPECT_GT(hits, int64_t(I.size() * 3 / 4));
  model.set_plane_ids(true, remap);  // no change: the cached raycast stays
  EXPECT_NE(model.last(), nullptr);

  model.set_plane_ids(false);
  EXPECT_EQ(model.last(), nullptr);
  model.model_at(T);
  EXPECT_EQ(model.last()->plane_ids.width(), 0);
}

}  // namespace
}  // namespace rrg
