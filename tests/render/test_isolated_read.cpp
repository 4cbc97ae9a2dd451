// render/isolated_read.h: a file's reader in a child process, stopped by its
// processor time, by its wall-clock time while it waits, and with its parent.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "render/isolated_read.h"

namespace morphoflow {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Whether process `pid` has ended (gone, or a zombie no one reaped yet).
bool ended(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;
  const size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
}

TEST(IsolatedRead, TheChildsBytesComeBackWhole) {
  std::string result, error;
  const std::string big(300000, 'x');  // more than a pipe holds at once
  ASSERT_TRUE(runIsolated([&] { return big + "end"; }, ReaderLimits{5.0, 30.0}, &result, &error)) << error;
  EXPECT_EQ(result, big + "end");
}

TEST(IsolatedRead, AReaderThatLoopsIsStoppedAtItsProcessorTime) {
  std::string result, error;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(runIsolated(
      [] {
        volatile unsigned long k = 0;
        for (;;) k = k + 1;
        return std::string();
      },
      ReaderLimits{1.0, 60.0}, &result, &error));
  EXPECT_NE(error.find("ran for more than 1 s"), std::string::npos) << error;
  EXPECT_LT(secondsSince(t0), 30.0);
}

TEST(IsolatedRead, AReaderThatWaitsIsStoppedAtItsWallClockTime) {
  // A blocked reader uses no processor time: only the wall clock ends it.
  std::string result, error;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(runIsolated(
      [] {
        ::pause();
        return std::string("never");
      },
      ReaderLimits{10.0, 1.0}, &result, &error));
  const double took = secondsSince(t0);
  EXPECT_NE(error.find("did not finish within 1 s"), std::string::npos) << error;
  EXPECT_GE(took, 0.9);
  EXPECT_LT(took, 10.0);
}

TEST(IsolatedRead, TheReaderEndsWithItsParent) {
  // A parent that runs a waiting reader, killed: its reader must not stay behind.
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t parent = ::fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    ::close(fds[0]);
    std::string result, error;
    runIsolated(
        [&] {
          const pid_t me = ::getpid();
          (void)!::write(fds[1], &me, sizeof me);
          ::pause();
          return std::string();
        },
        ReaderLimits{60.0, 600.0}, &result, &error);
    ::_exit(0);
  }
  ::close(fds[1]);
  pid_t reader = 0;
  ASSERT_EQ(::read(fds[0], &reader, sizeof reader), ssize_t(sizeof reader));
  ::close(fds[0]);
  ::kill(parent, SIGKILL);
  int status = 0;
  ::waitpid(parent, &status, 0);
  const auto t0 = std::chrono::steady_clock::now();
  while (!ended(reader) && secondsSince(t0) < 10.0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(ended(reader)) << "the reader " << reader << " outlived its parent";
  if (!ended(reader)) ::kill(reader, SIGKILL);
}

}  // namespace
}  // namespace morphoflow
