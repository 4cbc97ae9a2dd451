// What the libFuzzer targets share: a scratch folder of their own per
// process, the rule that a UserError (or a NonFiniteError: a diverged run)
// is the right answer to bad input and anything else is a bug, and seeds
// written by the target itself (MORPHOFLOW_FUZZ_SEEDS=DIR), so that the
// corpus starts from files of the format this build writes.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"

namespace morphoflow::fuzz {

// TMPDIR/morphoflow-fuzz-PID/NAME, emptied (all of it removed at exit).
inline std::filesystem::path freshScratch(const std::string& name) {
  static const std::filesystem::path root = [] {
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(
          std::filesystem::temp_directory_path() / ("morphoflow-fuzz-" + std::to_string(getpid())), ec);
    });
    return std::filesystem::temp_directory_path() / ("morphoflow-fuzz-" + std::to_string(getpid()));
  }();
  const std::filesystem::path dir = root / name;
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  std::filesystem::create_directories(dir);
  return dir;
}

// (A folder the input cannot make, one whose path runs through a file it
// wrote before, is left unwritten: the input then describes fewer files.)
inline void writeBytes(const std::filesystem::path& file, std::string_view bytes) {
  std::error_code ec;
  std::filesystem::create_directories(file.parent_path(), ec);
  if (ec) return;
  std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

inline std::string readBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A finding: said on stderr, then the fuzzer's abort.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "%s\n", what.c_str());
  std::abort();
}

// The text's non-empty lines (one --set override each).
inline std::vector<std::string> nonEmptyLines(std::string_view text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start < text.size()) {
    const size_t end = std::min(text.find('\n', start), text.size());
    if (end > start) out.emplace_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

// Runs f; a UserError or NonFiniteError is fine (said on stderr with
// MORPHOFLOW_FUZZ_VERBOSE=1, to see how deep an input went), any other
// exception aborts.
template <class F>
void expectUserErrorsOnly(F&& f) {
  static const bool verbose = std::getenv("MORPHOFLOW_FUZZ_VERBOSE") != nullptr;
  try {
    f();
    if (verbose) std::fprintf(stderr, "answered without an error\n");
  } catch (const UserError& e) {
    if (verbose) std::fprintf(stderr, "UserError: %s\n", e.what());
  } catch (const NonFiniteError& e) {
    if (verbose) std::fprintf(stderr, "NonFiniteError: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "not a UserError: %s\n", e.what());
    std::abort();
  }
}

// Keeps the target on one thread. A file's reader child
// (render/isolated_read.h) forked while a TBB worker held the allocator's
// lock of clang 14's ASan, which has no fork handler, waits for it for good
// (stopped at its wall-clock limit, a timeout to the fuzzer); glibc's malloc
// takes its locks across a fork, so the program itself does not.
inline void runOnOneThread() { static const ThreadLimit one(1); }

// Calls write(dir) when MORPHOFLOW_FUZZ_SEEDS names a folder, then exits.
template <class F>
void writeSeedsIfAsked(F&& write) {
  const char* dir = std::getenv("MORPHOFLOW_FUZZ_SEEDS");
  if (!dir || !*dir) return;
  std::filesystem::create_directories(dir);
  write(std::filesystem::path(dir));
  std::exit(0);
}

}  // namespace morphoflow::fuzz
