// Placeholder while the module is being written; replaced by the real command.
#include "client/commands/command.h"

#include <stdexcept>

namespace rrg::cli {

void register_planes_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("planes", "(being written)");
  cmd->callback([] { throw std::runtime_error("planes: not implemented yet"); });
}

}  // namespace rrg::cli
