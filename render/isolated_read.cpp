#include "render/isolated_read.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>

namespace morphoflow {

namespace {

// The reader's whole output from `fd` within `wallSeconds`: false when the
// time ran out first (the reader may be blocked, using no processor time).
bool readAll(int fd, double wallSeconds, std::string* got) {
  using Clock = std::chrono::steady_clock;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wallSeconds));
  char buf[1 << 16];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min<long long>(left, 60000)));
    if (ready < 0 && errno != EINTR) return true;  // the pipe is unusable: the answer is what came
    if (ready <= 0) continue;
    const ssize_t r = ::read(fd, buf, sizeof buf);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return true;
    got->append(buf, size_t(r));
  }
}

// In the child, between fork and exec: only async-signal-safe calls.
[[noreturn]] void execReader(char* const* argv, int out, int null, pid_t parent, double cpuSeconds) {
  if (::dup2(out, STDOUT_FILENO) < 0 || ::dup2(null, STDIN_FILENO) < 0 || ::dup2(null, STDERR_FILENO) < 0) ::_exit(126);
  // The reader ends with the process that waits for it (no reader left
  // behind, blocked, when a run is killed); the setting outlives the exec.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(126);
  ::close_range(3, ~0u, 0);  // nothing of this process's open files goes with the reader
  const rlim_t cpu = rlim_t(std::ceil(cpuSeconds));
  const rlimit limit{cpu, cpu + 1};  // SIGXCPU at the soft limit, SIGKILL at the hard one
  ::setrlimit(RLIMIT_CPU, &limit);
  ::execv(argv[0], argv);
  ::_exit(127);
}

std::string whyItStopped(int status, const ReaderLimits& limits, const std::string& program) {
  if (WIFSIGNALED(status) && (WTERMSIG(status) == SIGXCPU || WTERMSIG(status) == SIGKILL))
    return "the file is damaged: its reader ran for more than " + std::to_string(long(std::ceil(limits.cpuSeconds))) +
           " s without finishing";
  if (WIFSIGNALED(status))
    return "the file is damaged: reading it crashed the reader (" + std::string(strsignal(WTERMSIG(status))) + ")";
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
    return "the reader " + program + " could not be started: build morphoflow again (scripts/setup)";
  return "the file is damaged: its reader stopped (status " +
         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
}

}  // namespace

bool runIsolated(const std::vector<std::string>& argv, const ReaderLimits& limits, std::string* out,
                 std::string* error) {
  out->clear();
  if (argv.empty() || ::access(argv[0].c_str(), X_OK) != 0) {
    *error = "the reader " + (argv.empty() ? std::string("(none)") : argv[0]) +
             " is missing or cannot run: build morphoflow again (scripts/setup)";
    return false;
  }
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    *error = std::string("cannot make a pipe for the reader: ") + std::strerror(errno);
    return false;
  }
  const int null = ::open("/dev/null", O_RDWR | O_CLOEXEC);
  const pid_t parent = ::getpid();
  const pid_t pid = null < 0 ? -1 : ::fork();
  if (pid == 0) execReader(args.data(), fds[1], null, parent, limits.cpuSeconds);
  const int forkErrno = errno;
  ::close(fds[1]);
  if (null >= 0) ::close(null);
  if (pid < 0) {
    ::close(fds[0]);
    *error = std::string("cannot start the reader: ") + std::strerror(forkErrno);
    return false;
  }
  const bool answered = readAll(fds[0], limits.wallSeconds, out);
  ::close(fds[0]);
  if (!answered) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!answered) {
    *error = "the file's reader did not finish within " + std::to_string(long(std::ceil(limits.wallSeconds))) +
             " s: the file system did not answer, or the reader is stuck";
    return false;
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    *error = whyItStopped(status, limits, argv[0]);
    return false;
  }
  return true;
}

void putRecord(std::string* s, const std::string& record) {
  const uint64_t n = record.size();
  s->append(reinterpret_cast<const char*>(&n), sizeof n);
  s->append(record);
}

std::vector<std::string> takeRecords(const std::string& s) {
  std::vector<std::string> records;
  for (size_t at = 0;;) {
    uint64_t n = 0;
    if (s.size() - at < sizeof n) break;
    std::memcpy(&n, s.data() + at, sizeof n);
    if (s.size() - at - sizeof n < n) break;
    records.push_back(s.substr(at + sizeof n, n));
    at += sizeof n + n;
  }
  return records;
}

}  // namespace morphoflow
