// `cia402 ecat-slave --realtime PRIO --lock-memory`: the priority's range, and a refusal that says
// what it takes, before any socket is opened or any drive made. The refusals run in a forked child
// that gave up root (setuid) with RLIMIT_RTPRIO and RLIMIT_MEMLOCK at 0, as an ordinary user is.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "replay_support.hpp"

namespace {

using cia402::test::run_tool;

TEST(ecat_slave_options, a_realtime_priority_outside_1_to_99_is_refused_with_exit_2) {
  for (const char* priority : {"0", "100"}) {
    const auto r = run_tool({"ecat-slave", "--iface", "no-such-if", "--realtime", priority});
    EXPECT_EQ(r.exit_code, 2) << priority;
    EXPECT_NE(r.err.find("--realtime: Value " + std::string(priority) + " not in range 1 to 99"), std::string::npos) << r.err;
  }
}

TEST(ecat_slave_options, help_offers_realtime_and_lock_memory) {
  const auto r = run_tool({"ecat-slave", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--realtime"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--lock-memory"), std::string::npos) << r.out;
}

// Runs the tool in a child without privileges; the child exits 0 when it exits 1
// saying `expected_text` and makes no drive.
bool holds_without_privileges(const std::vector<std::string>& args, const std::string& expected_text) {
  const pid_t child = ::fork();
  if (child == 0) {
    const rlimit none{0, 0};
    if (::setrlimit(RLIMIT_RTPRIO, &none) != 0 || ::setrlimit(RLIMIT_MEMLOCK, &none) != 0 || ::setgid(65534) != 0 ||
        ::setuid(65534) != 0) {
      ::_exit(3);
    }
    const auto r = run_tool(args);
    const bool ok = r.exit_code == 1 && r.err.find(expected_text) != std::string::npos &&
                    r.out.find("drive(s) on") == std::string::npos;
    if (!ok) std::fprintf(stderr, "exit %d, err: %s\n", r.exit_code, r.err.c_str());  // why, in the test's log
    ::_exit(ok ? 0 : 1);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

TEST(ecat_slave_options, realtime_not_permitted_exits_1_naming_sched_fifo_and_what_it_needs) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to fork a child that gives root up";
  EXPECT_TRUE(holds_without_privileges({"ecat-slave", "--iface", "lo", "--realtime", "50"},
                                       "--realtime 50: SCHED_FIFO refused"));
  EXPECT_TRUE(holds_without_privileges({"ecat-slave", "--iface", "lo", "--realtime", "50"}, "CAP_SYS_NICE"));
}

TEST(ecat_slave_options, locked_memory_not_permitted_exits_1_naming_mlockall_and_what_it_needs) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to fork a child that gives root up";
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer replaces mlockall with one that always succeeds";
#endif
  EXPECT_TRUE(holds_without_privileges({"ecat-slave", "--iface", "lo", "--lock-memory"},
                                       "--lock-memory: mlockall refused"));
  EXPECT_TRUE(holds_without_privileges({"ecat-slave", "--iface", "lo", "--lock-memory"}, "CAP_IPC_LOCK"));
}

}  // namespace
