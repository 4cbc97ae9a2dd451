// Output files that cannot be lost or turned against the user: every file is
// written whole to a temporary name beside its final one, every write is
// checked (a full disk, a missing permission), and only a complete file is
// renamed into place. An existing device node, pipe or folder at the final
// path is never replaced. Failures are OutputErrors (exit 2) naming the path.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "core/error.h"

namespace morphoflow {

class OutputError : public UserError {
 public:
  OutputError(const std::filesystem::path& path, const std::string& message, const std::string& hint = {})
      : UserError({path.string(), 0, 0}, "", message, hint) {}
};

// A file written piece by piece under a temporary name beside `path`, every
// write checked; commit() fsyncs it and renames it into place. Destroyed
// without commit() (an error, an exception), it removes the temporary file.
class AtomicFile {
 public:
  explicit AtomicFile(const std::filesystem::path& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  void write(const void* data, size_t bytes);
  void commit();

 private:
  void abandon();
  [[noreturn]] void failWith(const char* what, int err);
  std::filesystem::path path_, tmp_;
  int fd_ = -1;
};

// Writes `bytes` to `path` (temporary name, checked writes, fsync, rename).
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// Throws OutputError when `path` exists and is not a regular file.
void checkReplaceable(const std::filesystem::path& path);

// Creates the folder `dir` (and its parents); throws OutputError when it is a
// file, under /proc, /sys or /dev, or cannot be created or written.
void createOutputFolder(const std::filesystem::path& dir);

// Before a command that writes one file at `file` does its work: the folder
// it goes in is a checked output folder (createOutputFolder), and the path
// is empty or a regular file (checkReplaceable); the option named in errors.
void checkOutputFile(const std::filesystem::path& file, const std::string& option);

// A scene's name made safe as a file stem: letters, digits, '-', '_' and
// '.' (no leading dot); anything else becomes '_'. Never empty, never a path.
std::string safeFileStem(const std::string& name);

}  // namespace morphoflow
