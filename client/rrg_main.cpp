// rrg: the command line tool. Subcommands register themselves from client/commands/.
#include "client/commands/command.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <exception>
#include <iostream>

int main(int argc, char** argv) {
  // Logs go to stderr so that stdout carries only results (tables, --json).
  spdlog::set_default_logger(spdlog::stderr_color_mt("rrg"));
  CLI::App app{"rrg - real-time reflection-aware Gaussian SLAM (RRG-SLAM) tools"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rrg 0.1.0");
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "debug logging");
  app.parse_complete_callback([&] { spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info); });

  rrg::cli::register_synth_command(app);
  rrg::cli::register_eval_command(app);
  rrg::cli::register_dataset_command(app);
  rrg::cli::register_device_command(app);
  rrg::cli::register_fuse_command(app);
  rrg::cli::register_track_command(app);
  rrg::cli::register_planes_command(app);
  rrg::cli::register_serve_command(app);
  rrg::cli::register_stream_command(app);
  rrg::cli::register_fetch_commands(app);
  rrg::cli::register_session_commands(app);
  rrg::cli::register_run_command(app);

  try {
    app.parse(argc, argv);
  } catch (const rrg::cli::ExitWith& e) {
    return e.code;
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help / version / the usage error
    return code == 0 ? 0 : rrg::cli::kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "rrg: error: " << e.what() << "\n";
    return rrg::cli::kExitFailure;
  }
  return 0;
}
