// The block hash's home slots (voxel_hash_device.h): every coordinate axis must reach the bits the
// mask keeps, or rows of blocks collide and every lookup walks a long probe chain.
#include "core/tsdf/voxel_hash_device.h"

#include <gtest/gtest.h>

#include <set>
#include <vector>

namespace rrg {
namespace {

// Blocks that differ in one coordinate only get (almost) distinct home slots on every axis.
TEST(VoxelHash, EveryAxisReachesTheHomeSlot) {
  const uint64_t mask = (uint64_t{1} << 16) - 1;
  for (int axis = 0; axis < 3; ++axis) {
    std::set<uint64_t> slots;
    for (int i = -32; i < 32; ++i) {
      const int x = axis == 0 ? i : 3, y = axis == 1 ? i : -5, z = axis == 2 ? i : 7;
      slots.insert(kernel::hash_slot(block_key(x, y, z), mask));
    }
    // 64 keys into 65,536 slots: a uniform hash collides about 0.03 times.
    EXPECT_GE(slots.size(), 62u) << "axis " << axis;
  }
}

// The blocks of a room's shell (5 × 3 × 5 m at 4 cm blocks: walls, floor, ceiling two blocks
// thick and a table) inserted at load ¼ (TsdfVolume keeps it ≤ ½): linear probing then
// needs about one probe per insert. (The old multiplicative slot averaged 65 and hit 518.)
TEST(VoxelHash, ARoomShellNeedsAboutOneProbePerBlock) {
  std::vector<uint64_t> keys;
  for (int x = 0; x < 125; ++x)
    for (int y = 0; y < 75; ++y)
      for (int z = 0; z < 125; ++z) {
        const bool shell = x < 2 || x > 122 || y < 2 || y > 72 || z < 2 || z > 122 ||
                           (y == 20 && x > 30 && x < 60 && z > 30 && z < 60);
        if (shell) keys.push_back(block_key(x - 60, y - 10, z - 60));
      }
  const size_t capacity = size_t{1} << 19;  // ≥ 4 slots per block
  ASSERT_LE(keys.size() * 2, capacity);
  std::vector<uint64_t> table_keys(capacity, kEmptyKey);
  std::vector<int32_t> table_values(capacity, -1);
  const kernel::HashView h{{table_keys.data(), int64_t(capacity)}, {table_values.data(), int64_t(capacity)}};
  const uint64_t mask = capacity - 1;
  double probes = 0;
  uint64_t worst = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    int64_t slot = -1;
    ASSERT_EQ(kernel::hash_insert(h, keys[i], slot), kernel::InsertResult::Inserted);
    h.values[slot] = int32_t(i);
    const uint64_t distance = (uint64_t(slot) - kernel::hash_slot(keys[i], mask)) & mask;
    probes += double(distance + 1);
    worst = std::max(worst, distance + 1);
  }
  EXPECT_LT(probes / double(keys.size()), 1.5);
  EXPECT_LT(worst, 32u);
  for (size_t i = 0; i < keys.size(); i += 97) EXPECT_EQ(kernel::hash_find(h, keys[i]), int32_t(i));
  EXPECT_EQ(kernel::hash_find(h, block_key(1000, 1000, 1000)), -1);
}

}  // namespace
}  // namespace rrg
