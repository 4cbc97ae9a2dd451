#include "render/isolated_read.h"

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

// In sanitizer builds, the callback a sanitizer runs before it ends the
// process (libFuzzer's records the input as a finding); null elsewhere.
extern "C" void __sanitizer_set_death_callback(void (*callback)(void)) __attribute__((weak));

namespace morphoflow {

namespace {

// The child dies of what kills it: the parent's handlers of fatal signals and
// its sanitizer death callback are the parent's business (the parent reports
// the crash as a damaged file).
void dieAlone() {
  for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL, SIGXCPU}) std::signal(sig, SIG_DFL);
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(nullptr);
}

bool writeAll(int fd, const char* p, size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w, n -= size_t(w);
  }
  return true;
}

// The child's whole answer from `fd` within `wallSeconds`: false when the
// time ran out first (the child may be blocked, using no processor time).
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

}  // namespace

bool runIsolated(const std::function<std::string()>& work, const ReaderLimits& limits, std::string* result,
                 std::string* error) {
  const double cpuSeconds = limits.cpuSeconds;
  int fds[2];
  if (::pipe(fds) != 0) {
    *error = std::string("cannot make a pipe for the reader: ") + std::strerror(errno);
    return false;
  }
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    *error = std::string("cannot start the reader: ") + std::strerror(errno);
    return false;
  }
  if (pid == 0) {  // the child: the work, its length and bytes, and out without running exit handlers
    ::close(fds[0]);
    dieAlone();
    // The reader ends with the process that waits for it (no reader left
    // behind, blocked, when a run is killed).
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(5);
    const rlim_t cpu = rlim_t(std::ceil(cpuSeconds));
    const rlimit limit{cpu, cpu + 1};  // SIGXCPU at the soft limit, SIGKILL at the hard one
    ::setrlimit(RLIMIT_CPU, &limit);
    std::string bytes;
    int status = 0;
    try {
      bytes = work();
    } catch (...) {
      status = 3;
    }
    const uint64_t n = bytes.size();
    if (status == 0 &&
        !(writeAll(fds[1], reinterpret_cast<const char*>(&n), sizeof n) && writeAll(fds[1], bytes.data(), n)))
      status = 4;
    ::_exit(status);
  }
  ::close(fds[1]);
  std::string got;
  const bool answered = readAll(fds[0], limits.wallSeconds, &got);
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
  uint64_t n = 0;
  if (WIFSIGNALED(status) && (WTERMSIG(status) == SIGXCPU || WTERMSIG(status) == SIGKILL)) {
    *error = "the file is damaged: its reader ran for more than " + std::to_string(long(std::ceil(cpuSeconds))) +
             " s without finishing";
    return false;
  }
  if (WIFSIGNALED(status)) {
    *error = "the file is damaged: reading it crashed the reader (" + std::string(strsignal(WTERMSIG(status))) + ")";
    return false;
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || got.size() < sizeof n) {
    *error = "the file is damaged: its reader stopped (status " +
             std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
    return false;
  }
  std::memcpy(&n, got.data(), sizeof n);
  if (got.size() - sizeof n != n) {
    *error = "the file is damaged: its reader's result was cut short";
    return false;
  }
  *result = got.substr(sizeof n);
  return true;
}

}  // namespace morphoflow
