// test_fuzz: the fuzz target over its seeds (every seed must decode) and over deterministic random
// mutations of them (they must only ever be refused with std::invalid_argument) - a short CI
// stand-in for the libFuzzer run of tests/fuzz/build_and_run.sh.
#include "tests/fuzz/frame_fuzz.h"

#include <gtest/gtest.h>

#include <random>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace rrg::fuzz {
namespace {

TEST(FrameFuzz, EverySeedDecodes) {
  const auto seeds = frame_fuzz_seeds();
  ASSERT_EQ(seeds.size(), size_t(4 * kFuzzModes));
  for (size_t i = 0; i < seeds.size(); ++i) {
    EXPECT_TRUE(decode_frame_input(seeds[i].data(), seeds[i].size())) << "seed " << i;
    EXPECT_EQ(LLVMFuzzerTestOneInput(seeds[i].data(), seeds[i].size()), 0);
  }
}

TEST(FrameFuzz, RandomMutationsNeverCrash) {
  const auto seeds = frame_fuzz_seeds();
  std::mt19937 rng(2024);
  int accepted = 0;
  constexpr int kRuns = 20000;
  for (int run = 0; run < kRuns; ++run) {
    std::vector<uint8_t> in = seeds[rng() % seeds.size()];
    switch (rng() % 4) {
      case 0:  // bit flips (not in the mode/size prefix)
        for (int k = 1 + int(rng() % 4); k > 0 && in.size() > 3; --k) in[3 + rng() % (in.size() - 3)] ^= uint8_t(1u << (rng() % 8));
        break;
      case 1:  // truncation
        in.resize(rng() % (in.size() + 1));
        break;
      case 2:  // random bytes overwritten
        for (int k = 1 + int(rng() % 8); k > 0 && !in.empty(); --k) in[rng() % in.size()] = uint8_t(rng());
        break;
      default:  // another expected size or decoder for the same payload
        if (in.size() >= 3) in[rng() % 3] = uint8_t(rng());
    }
    accepted += decode_frame_input(in.data(), in.size()) ? 1 : 0;
  }
  std::printf("%d mutated frames, %d accepted, the rest refused with std::invalid_argument\n", kRuns, accepted);
}

}  // namespace
}  // namespace rrg::fuzz
