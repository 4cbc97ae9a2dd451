// Child processes of a batch: the morphoflow executable itself, started with
// an argument vector (no shell), its stdout and stderr into a file, so a
// crash, an abort or the out-of-memory killer in one scene never stops the
// others.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace morphoflow {

// How a child ended: its exit status, or the signal that killed it.
struct ChildExit {
  int code = 0;    // exit status when it exited
  int signal = 0;  // the signal when one killed it, else 0
};

class ChildProcess {
 public:
  // Starts `exe args...` with stdout and stderr appended to `log`.
  ChildProcess(const std::string& exe, const std::vector<std::string>& args, const std::filesystem::path& log);
  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&&) = delete;
  ~ChildProcess();  // waits for a child that is still running (never leaves a zombie)

  pid_t pid() const { return pid_; }
  // The exit, once the child has ended; never blocks.
  std::optional<ChildExit> poll();
  void signal(int sig) const;

 private:
  pid_t pid_ = -1;
  std::optional<ChildExit> exit_;
};

// The running executable's path (/proc/self/exe).
std::string selfExecutable();

// "SIGSEGV", "SIGKILL", ...
std::string signalName(int sig);

}  // namespace morphoflow
