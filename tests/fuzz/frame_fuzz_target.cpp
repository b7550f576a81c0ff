// libFuzzer entry point over frame decoding (tests/fuzz/build_and_run.sh builds it with clang and
// -fsanitize=fuzzer,address). In the GCC test build this file only adds the symbol to test_fuzz.
#include "tests/fuzz/frame_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rrg::fuzz::decode_frame_input(data, size);
  return 0;
}
