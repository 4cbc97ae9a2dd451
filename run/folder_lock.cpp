#include "run/folder_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <string>

#include <fmt/format.h>

#include "core/error.h"

namespace morphoflow {

FolderLock::FolderLock(const std::filesystem::path& folder, const std::string& name) {
  const std::filesystem::path file = folder / name;
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0) return;  // (an unwritable folder fails, naming itself, at its first output)
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    if (err != EWOULDBLOCK) return;  // no locks on this filesystem: run unlocked
    char text[64] = {};
    const ssize_t n = ::pread(fd_, text, sizeof text - 1, 0);
    ::close(fd_);
    fd_ = -1;
    const std::string holder = n > 0 ? std::string(text, size_t(n)) : std::string("another process");
    throw UserError(
        {folder.string(), 0, 0}, "",
        "the output folder is in use by another morphoflow run (" + holder.substr(0, holder.find('\n')) + ")",
        "wait for it to end, or give another --out");
  }
  const std::string me = fmt::format("pid {}\n", ::getpid());
  if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, me.data(), me.size(), 0) < 0) {
  }
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // (closing releases the lock)
}

void stopWithBatchParent() {
  const char* parent = std::getenv(kBatchParentVariable);
  if (!parent) return;
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (std::to_string(::getppid()) != parent) ::raise(SIGTERM);  // the batch died before the request
}

}  // namespace morphoflow
