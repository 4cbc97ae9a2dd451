// Helpers for tests that drive the morphoflow executable.
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace morphoflow::testing {

struct CommandResult {
  int status = -1;
  std::string output;  // stdout and stderr together
};

inline CommandResult runMorphoflow(const std::string& args) {
  std::string cmd = std::string(MORPHOFLOW_BINARY) + " " + args + " 2>&1";
  CommandResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

inline std::filesystem::path tempDir(const std::string& name) {
  auto d = std::filesystem::temp_directory_path() / ("morphoflow_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline std::string sceneFile(const std::string& name) {
  return std::string(MORPHOFLOW_SOURCE_DIR) + "/scenes/" + name;
}

// Reads a two-column CSV with a header line.
inline std::vector<std::pair<double, double>> readCsv2(const std::filesystem::path& p) {
  std::vector<std::pair<double, double>> rows;
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string a, b;
    if (std::getline(ss, a, ',') && std::getline(ss, b, ',')) rows.emplace_back(std::stod(a), std::stod(b));
  }
  return rows;
}

// Linear interpolation in sorted (x, y) rows.
inline double interpolate(const std::vector<std::pair<double, double>>& rows, double x) {
  for (size_t i = 1; i < rows.size(); ++i)
    if (x <= rows[i].first) {
      double t = (x - rows[i - 1].first) / (rows[i].first - rows[i - 1].first);
      return rows[i - 1].second + t * (rows[i].second - rows[i - 1].second);
    }
  return rows.back().second;
}

inline bool fullValidation() { return std::getenv("MORPHOFLOW_FULL_VALIDATION") != nullptr; }

// morphoflow started in the background with an argument vector (stdout and
// stderr to `log`); its pid.
inline pid_t startMorphoflow(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<std::string> all = {MORPHOFLOW_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::error_code ec;
  std::filesystem::create_directories(log.parent_path(), ec);  // (a log it cannot open: no child)
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  if (posix_spawn(&pid, MORPHOFLOW_BINARY, &fa, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

// Waits for a child; its exit status, or 128 + the signal that ended it.
inline int waitMorphoflow(pid_t pid) {
  int st = 0;
  while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(st) ? WEXITSTATUS(st) : WIFSIGNALED(st) ? 128 + WTERMSIG(st) : -1;
}

// Polls until `ready()` holds or `seconds` pass; whether it held.
template <class F>
bool waitUntil(F ready, double seconds) {
  for (int i = 0; i < int(seconds * 200); ++i) {
    if (ready()) return true;
    usleep(5000);
  }
  return ready();
}

}  // namespace morphoflow::testing
