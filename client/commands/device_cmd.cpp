// rrg devices: which back ends this build has and which devices it can use.
#include "client/commands/command.h"
#include "core/common/device.h"

#include <omp.h>

#include <iostream>

namespace rrg::cli {

void register_device_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("devices", "list the compute devices this build can use");
  cmd->callback([] {
    std::cout << "cpu      : " << omp_get_max_threads() << " threads (always available, the oracle)\n";
    if (!cuda_compiled()) {
      std::cout << "cuda     : not compiled in (build with nvcc, -DRRG_CUDA=ON)\n";
    } else if (cuda_device_count() == 0) {
      std::cout << "cuda     : compiled in, no usable GPU found\n";
    } else {
      for (int i = 0; i < cuda_device_count(); ++i)
        std::cout << "cuda:" << i << "   : " << cuda_device_name(i) << "\n";
    }
    std::cout << "default  : " << default_device().to_string() << "\n";
  });
}

}  // namespace rrg::cli
