#pragma once
// Ctrl-C for long commands (`rrg run`, `rrg track`, `rrg fuse`, `rrg planes eval`): while a StopOnSignal is alive, the first SIGINT
// or SIGTERM only records itself, so the command can stop after the frame in progress and still
// write its outputs; it then ends with ExitWith{128 + signal}. A second signal aborts at once.
#include "client/commands/command.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstddef>
#include <cstdio>

namespace rrg::cli {

// The handler only sets the flag, writes one line and puts the default action back, so a second
// signal ends the process at once. The handlers before a StopOnSignal are restored when it ends.
inline std::atomic<int> g_stop_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" inline void request_stop(int sig) {
  g_stop_signal.store(sig);
  constexpr char kMsg[] = "\nrrg: stopping after this frame and writing the outputs; press Ctrl-C again to abort\n";
  [[maybe_unused]] const ssize_t n = write(STDERR_FILENO, kMsg, sizeof(kMsg) - 1);
  std::signal(sig, SIG_DFL);
}

class StopOnSignal {
 public:
  StopOnSignal() : old_int_(std::signal(SIGINT, request_stop)), old_term_(std::signal(SIGTERM, request_stop)) {
    g_stop_signal.store(0);
  }
  ~StopOnSignal() {
    std::signal(SIGINT, old_int_);
    std::signal(SIGTERM, old_term_);
  }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;
  int signal() const { return g_stop_signal.load(); }  // 0 while none arrived
  int exit_code() const { return 128 + (signal() != 0 ? signal() : SIGINT); }  // the shell's code for a job it ended
  // The end of a command that stopped early and wrote what it had: says so, then exits 128 + signal.
  [[noreturn]] void finish_interrupted(size_t frames) const {
    std::printf("interrupted after %zu frames; the outputs above cover those frames\n", frames);
    throw ExitWith{exit_code()};
  }

 private:
  void (*old_int_)(int);
  void (*old_term_)(int);
};

}  // namespace rrg::cli
