// The voxel's fixed-point codec (voxel.h): known answers, clamping, NaN, and block-key ranges.
#include "core/tsdf/voxel.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rrg {
namespace {

TEST(VoxelCodec, TsdfKnownAnswersAndClamping) {
  using namespace voxel_codec;
  EXPECT_EQ(encode_tsdf(0.0f), 0);
  EXPECT_EQ(encode_tsdf(1.0f), 32767);
  EXPECT_EQ(encode_tsdf(-1.0f), -32767);
  EXPECT_EQ(encode_tsdf(3.0f), 32767);
  EXPECT_EQ(encode_tsdf(-3.0f), -32767);
  EXPECT_EQ(encode_tsdf(0.5f / 32767.0f), 1);    // half a step rounds away from zero
  EXPECT_EQ(encode_tsdf(-0.5f / 32767.0f), -1);
  EXPECT_EQ(encode_tsdf(NAN), -32767);           // as fminf(fmaxf(NaN, −1), 1) = −1
  for (const float t : {-0.73f, -0.1f, 0.2f, 0.999f}) EXPECT_NEAR(decode_tsdf(encode_tsdf(t)), t, 0.5f / 32767.0f);
}

TEST(VoxelCodec, UnitKnownAnswersAndClamping) {
  using namespace voxel_codec;
  EXPECT_EQ(encode_unit(0.0f), 0);
  EXPECT_EQ(encode_unit(1.0f), 65535);
  EXPECT_EQ(encode_unit(-0.2f), 0);
  EXPECT_EQ(encode_unit(1.7f), 65535);
  EXPECT_EQ(encode_unit(NAN), 0);
  for (const float c : {0.01f, 0.5f, 0.87f}) EXPECT_NEAR(decode_unit(encode_unit(c)), c, 0.5f / 65535.0f);
}

TEST(VoxelCodec, BlockKeysCoverTheirRangeOnly) {
  EXPECT_TRUE(block_in_range(0, 0, 0));
  EXPECT_TRUE(block_in_range(-kKeyBias, kKeyBias - 1, -kKeyBias));
  EXPECT_FALSE(block_in_range(kKeyBias, 0, 0));
  EXPECT_FALSE(block_in_range(0, -kKeyBias - 1, 0));
  EXPECT_FALSE(block_in_range(0, 0, 1 << 30));
  EXPECT_FALSE(block_in_range(0, 0, -(1 << 30)));
  for (const auto& c : {Eigen::Vector3i(-kKeyBias, 5, kKeyBias - 1), Eigen::Vector3i(-3, -70000, 12)})
    EXPECT_EQ(block_coord(block_key(c.x(), c.y(), c.z())), c);
}

}  // namespace
}  // namespace rrg
