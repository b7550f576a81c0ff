#pragma once
// The frame-decoding fuzz target (libFuzzer entry point in frame_fuzz_target.cpp) and its seeds.
// Input layout: byte 0 picks the decoder (kFuzzModes), bytes 1 and 2 the expected width and height
// (1 + b % 48), the rest is the encoded payload. Only std::invalid_argument may escape a decoder;
// anything else (another exception, a crash, an ASan report, an RVL stream that decodes but does
// not re-encode to itself) is a finding.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rrg::fuzz {

// color raw/png/jpeg, depth raw_u16/png_u16/rvl/rvl_zstd/raw_f32, labels rvl.
inline constexpr int kFuzzModes = 9;

// Runs one input; returns whether the decoder accepted it.
bool decode_frame_input(const uint8_t* data, size_t size);

// Valid inputs for every mode (a few sizes and contents), for the corpus and the smoke test.
std::vector<std::vector<uint8_t>> frame_fuzz_seeds();

}  // namespace rrg::fuzz
