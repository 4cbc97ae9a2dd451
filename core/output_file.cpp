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
    throw OutputError(path,
                      "an output would replace something that is not a regular file (a folder, device, pipe or link)",
                      "move it away or choose another --out");
}

AtomicFile::AtomicFile(const fs::path& path) : path_(path), tmp_(path) {
  checkReplaceable(path_);
  tmp_ += ".tmp";
  checkReplaceable(tmp_);
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0) fail(path_, "cannot create the file", errno);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) abandon();
}

void AtomicFile::abandon() {
  ::close(fd_);
  fd_ = -1;
  ::unlink(tmp_.c_str());
}

void AtomicFile::failWith(const char* what, int err) {
  abandon();
  fail(path_, what, err);
}

void AtomicFile::write(const void* data, size_t bytes) {
  const char* p = static_cast<const char*>(data);
  size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::write(fd_, p + done, bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) failWith("cannot write the file", n < 0 ? errno : ENOSPC);
    done += size_t(n);
  }
}

void AtomicFile::commit() {
  // A full disk may only show at fsync or close (delayed allocation, NFS).
  if (::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS) failWith("cannot write the file", errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp_.c_str());
    fail(path_, "cannot write the file", err);
  }
  if (::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp_.c_str());
    fail(path_, "cannot move the finished file into place", err);
  }
}

void writeFileAtomically(const fs::path& path, std::string_view bytes) {
  AtomicFile f(path);
  f.write(bytes.data(), bytes.size());
  f.commit();
}

void createOutputFolder(const fs::path& dir) {
  if (dir.empty()) throw OutputError("--out", "names no folder (it is empty)", "give --out DIR");
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

void checkOutputFile(const fs::path& file, const std::string& option) {
  if (file.empty() || file.filename().empty() || file.filename() == "." || file.filename() == "..")
    throw OutputError(file, "is not a file name", "give " + option + " a file path");
  const fs::path parent = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  createOutputFolder(parent);
  checkReplaceable(file);
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
