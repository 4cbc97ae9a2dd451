// render/isolated_read.h: a file's reader as a program in a process of its
// own, stopped by its processor time, by its wall-clock time while it waits,
// and with its parent; its answers as records.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
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

std::vector<std::string> shell(const std::string& script) { return {"/bin/sh", "-c", script}; }

TEST(IsolatedRead, TheReadersOutputComesBackWhole) {
  std::string out, error;
  // More than a pipe holds at once.
  ASSERT_TRUE(
      runIsolated(shell("head -c 300000 /dev/zero | tr '\\0' x; printf end"), ReaderLimits{5.0, 30.0}, &out, &error))
      << error;
  EXPECT_EQ(out, std::string(300000, 'x') + "end");
}

TEST(IsolatedRead, AReaderThatLoopsIsStoppedAtItsProcessorTime) {
  std::string out, error;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(runIsolated(shell("while :; do :; done"), ReaderLimits{1.0, 60.0}, &out, &error));
  EXPECT_NE(error.find("ran for more than 1 s"), std::string::npos) << error;
  EXPECT_LT(secondsSince(t0), 30.0);
}

TEST(IsolatedRead, AReaderThatWaitsIsStoppedAtItsWallClockTime) {
  // A blocked reader uses no processor time: only the wall clock ends it.
  std::string out, error;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(runIsolated(shell("printf partial; exec sleep 600"), ReaderLimits{10.0, 2.0}, &out, &error));
  const double took = secondsSince(t0);
  EXPECT_NE(error.find("did not finish within 2 s"), std::string::npos) << error;
  EXPECT_EQ(out, "partial");  // what it wrote before it was stopped
  EXPECT_GE(took, 1.9);
  EXPECT_LT(took, 20.0);
}

TEST(IsolatedRead, AReaderThatCrashesOrFailsIsNamedSo) {
  std::string out, error;
  EXPECT_FALSE(runIsolated(shell("kill -SEGV $$"), ReaderLimits{}, &out, &error));
  EXPECT_NE(error.find("crashed the reader (Segmentation fault)"), std::string::npos) << error;
  EXPECT_FALSE(runIsolated(shell("exit 3"), ReaderLimits{}, &out, &error));
  EXPECT_NE(error.find("its reader stopped (status 3)"), std::string::npos) << error;
  EXPECT_FALSE(runIsolated({"/nonexistent/morphoflow-vdb-reader", "time"}, ReaderLimits{}, &out, &error));
  EXPECT_NE(error.find("/nonexistent/morphoflow-vdb-reader is missing"), std::string::npos) << error;
}

// The reader runs with nothing of this process's but its arguments: its
// standard input is empty and this process's open files stay here.
TEST(IsolatedRead, TheReaderGetsOnlyItsArguments) {
  const std::filesystem::path kept =
      std::filesystem::temp_directory_path() / ("morphoflow_reader_kept_" + std::to_string(::getpid()));
  std::FILE* open = std::fopen(kept.c_str(), "w");  // inherited by a child that does not close it
  ASSERT_NE(open, nullptr);
  std::string out, error;
  const bool ok =
      runIsolated({"/bin/sh", "-c", "printf '%s|' \"$1\"; cat; printf '|'; exec ls /proc/self/fd", "sh", "an argument"},
                  ReaderLimits{5.0, 30.0}, &out, &error);
  std::fclose(open);
  std::filesystem::remove(kept);
  ASSERT_TRUE(ok) << error;
  EXPECT_EQ(out, "an argument||0\n1\n2\n3\n");  // 3: the folder ls lists
}

TEST(IsolatedRead, RecordsRoundTripAndACutOneIsLeftOut) {
  std::string s;
  putRecord(&s, "one");
  putRecord(&s, std::string("t\0wo", 4));
  putRecord(&s, "");
  putRecord(&s, "cut");
  const std::vector<std::string> whole = takeRecords(s.substr(0, s.size() - 1));
  ASSERT_EQ(whole.size(), 3u);
  EXPECT_EQ(whole[0], "one");
  EXPECT_EQ(whole[1], std::string("t\0wo", 4));
  EXPECT_EQ(whole[2], "");
  EXPECT_EQ(takeRecords(s).size(), 4u);
}

TEST(IsolatedRead, TheReaderEndsWithItsParent) {
  // A parent that runs a waiting reader, killed: its reader must not stay behind.
  const std::filesystem::path pidFile =
      std::filesystem::temp_directory_path() / ("morphoflow_reader_pid_" + std::to_string(::getpid()));
  std::filesystem::remove(pidFile);
  const pid_t parent = ::fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    std::string out, error;
    runIsolated(shell("echo $$ > " + pidFile.string() + ".tmp && mv " + pidFile.string() + ".tmp " + pidFile.string() +
                      " && exec sleep 600"),
                ReaderLimits{60.0, 600.0}, &out, &error);
    ::_exit(0);
  }
  const auto t0 = std::chrono::steady_clock::now();
  while (!std::filesystem::exists(pidFile) && secondsSince(t0) < 10.0)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  pid_t reader = 0;
  ASSERT_TRUE(std::ifstream(pidFile) >> reader) << "the reader did not start";
  std::filesystem::remove(pidFile);
  ::kill(parent, SIGKILL);
  int status = 0;
  ::waitpid(parent, &status, 0);
  const auto t1 = std::chrono::steady_clock::now();
  while (!ended(reader) && secondsSince(t1) < 10.0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(ended(reader)) << "the reader " << reader << " outlived its parent";
  if (!ended(reader)) ::kill(reader, SIGKILL);
}

}  // namespace
}  // namespace morphoflow
