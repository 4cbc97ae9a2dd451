#include "core/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

std::string why(int err) {
  return err == ENOSPC   ? "the disk is full"
         : err == EDQUOT ? "the disk quota is exceeded"
         : err == EFBIG  ? "the file is larger than this process may write"
                         : std::strerror(err);
}

std::string hintFor(int err) {
  if (err == ENOSPC || err == EDQUOT || err == EFBIG) return "free some space or choose another --out";
  if (err == EACCES || err == EPERM || err == EROFS) return "choose an --out you may write to";
  return {};
}

[[noreturn]] void fail(const fs::path& path, const std::string& what, int err) {
  throw OutputError(path, what + ": " + why(err), hintFor(err));
}

}  // namespace

void checkReplaceable(const fs::path& path) {
  struct stat st;
  if (::lstat(path.c_str(), &st) != 0) return;  // nothing there
  if (!S_ISREG(st.st_mode))
    throw OutputError(path, "an output would replace something that is not a regular file (a folder, device, pipe or link)",
                      "move it away or choose another --out");
}

void writeFileAtomically(const fs::path& path, std::string_view bytes) {
  checkReplaceable(path);
  fs::path tmp = path;
  tmp += ".tmp";
  checkReplaceable(tmp);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) fail(path, "cannot create the file", errno);
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      ::close(fd);
      ::unlink(tmp.c_str());
      fail(path, "cannot write the file", err);
    }
    done += size_t(n);
  }
  // A full disk may only show at fsync or close (delayed allocation, NFS).
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    fail(path, "cannot write the file", err);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "cannot write the file", err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "cannot move the finished file into place", err);
  }
}

void createOutputFolder(const fs::path& dir) {
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  for (const char* system : {"/proc", "/sys", "/dev"}) {
    const fs::path root(system);
    auto [a, b] = std::mismatch(root.begin(), root.end(), abs.begin(), abs.end());
    if (a == root.end())
      throw OutputError(dir, std::string("is under ") + system + ", which holds no files a run may write",
                        "choose another --out");
  }
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw OutputError(dir, "exists and is not a folder", "choose another --out, or move the file away");
  fs::create_directories(dir, ec);
  if (ec) fail(dir, "cannot create the folder", ec.value());
  if (::access(dir.c_str(), W_OK | X_OK) != 0) fail(dir, "cannot write into the folder", errno);
}

std::string safeFileStem(const std::string& name) {
  std::string s;
  for (char ch : name) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '-' ||
                    ch == '_' || ch == '.';
    s += ok ? ch : '_';
  }
  while (!s.empty() && s.front() == '.') s.front() = '_';
  if (s.empty()) s = "scene";
  if (s.size() > 200) s.resize(200);
  return s;
}

}  // namespace morphoflow
