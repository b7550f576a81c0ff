// Start-up check that the CPU has the instruction set the program was built for (RRG_CPU_ARCH,
// cmake/cpu_arch.cmake). Compiled for the baseline x86-64 and run as a constructor of priority 101,
// before the C++ static initialisers of the rest of the program (which may already use AVX2), so
// a CPU without it gets a message and exit code 70 instead of an illegal-instruction crash.
// RRG_CPU_CHECK_FAIL=1 in the environment takes the failing path (tests/common/cpu_check_test.cpp).
#include <cstdlib>
#include <cstring>
#include <unistd.h>

namespace {

void write_stderr(const char* s) {
  const ssize_t n = write(2, s, strlen(s));
  (void)n;
}

[[gnu::constructor(101)]] void rrg_check_cpu_level() {
  constexpr const char* level = RRG_CPU_LEVEL;  // "" when the build targets no x86-64-vN level
  if (level[0] == '\0') return;
  bool ok = true;
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (strcmp(level, "x86-64-v2") == 0) ok = __builtin_cpu_supports("x86-64-v2");
  else if (strcmp(level, "x86-64-v3") == 0) ok = __builtin_cpu_supports("x86-64-v3");
  else if (strcmp(level, "x86-64-v4") == 0) ok = __builtin_cpu_supports("x86-64-v4");
#endif
  const char* force = getenv("RRG_CPU_CHECK_FAIL");
  if (force != nullptr && strcmp(force, "1") == 0) ok = false;
  if (ok) return;
  write_stderr("error: this program was built for ");
  write_stderr(level);
  write_stderr(" CPUs (-march, cmake/cpu_arch.cmake; x86-64-v3 means AVX2 and FMA) and this CPU lacks that "
               "instruction set. Rebuild with -DRRG_CPU_ARCH= (the compiler's default) or -DRRG_CPU_ARCH=native.\n");
  _exit(70);  // EX_SOFTWARE
}

}  // namespace
