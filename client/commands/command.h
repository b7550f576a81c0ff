#pragma once
// Each `rrg` subcommand lives in one file under client/commands/ and registers itself here.
// A command's callback throws on error; rrg_main turns the exception into a message and exit code.
#include <CLI/CLI.hpp>

namespace rrg::cli {

// Exit codes: 0 ok, 1 runtime failure (bad data, I/O), 2 usage error (bad or missing flags).
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

// Thrown by a command that finished its work but must end with a given exit code (e.g. `rrg run`
// stopped by a signal: 128 + the signal, after writing its outputs); rrg_main returns the code.
struct ExitWith {
  int code;
};

void register_synth_command(CLI::App& app);    // rrg synth
void register_eval_command(CLI::App& app);     // rrg eval ate|images|mesh
void register_dataset_command(CLI::App& app);  // rrg dataset info
void register_device_command(CLI::App& app);   // rrg devices
void register_fuse_command(CLI::App& app);     // rrg fuse (TSDF from a posed dataset -> mesh)
void register_track_command(CLI::App& app);    // rrg track (tracking + TSDF fusion on a dataset)
void register_planes_command(CLI::App& app);   // rrg planes (reflective plane identification)
// The service (issue #9; without gRPC these say the build has none):
void register_serve_command(CLI::App& app);     // rrg serve
void register_stream_command(CLI::App& app);    // rrg stream
void register_fetch_commands(CLI::App& app);    // rrg render | mesh | gaussians
void register_session_commands(CLI::App& app);  // rrg sessions | save | load | drain | health
void register_run_command(CLI::App& app);      // rrg run (the whole pipeline on a dataset, with evaluation)

}  // namespace rrg::cli
