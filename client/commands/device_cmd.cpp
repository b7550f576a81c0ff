// Placeholder while the module is being written; replaced by the real command.
#include "client/commands/command.h"

#include <stdexcept>

namespace rrg::cli {

void register_device_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("device", "(being written)");
  cmd->callback([] { throw std::runtime_error("device: not implemented yet"); });
}

}  // namespace rrg::cli
