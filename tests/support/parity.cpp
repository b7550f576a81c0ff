#include "tests/support/parity.h"

#include <mutex>

namespace rrg::test {

void report_cuda_parity_status() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (!cuda_compiled())
      std::cout << "[parity] CUDA half skipped: this build has no CUDA back end\n";
    else if (cuda_device_count() == 0)
      std::cout << "[parity] CUDA half skipped: CUDA compiled in, but no usable GPU here\n";
    else
      std::cout << "[parity] comparing cpu with " << cuda_device_count() << " CUDA device(s): "
                << cuda_device_name(0) << "\n";
  });
}

}  // namespace rrg::test
