// morphoflow-vdb-reader MODE PATH...: reads each .vdb file as MODE says
// (render/vdb_read_here.h) and writes one answer per file to its standard
// output, as records (render/isolated_read.h). The library runs it for every
// .vdb file it reads, in a process of its own; it is not meant to be run by hand.
#include <unistd.h>

#include <cerrno>
#include <exception>
#include <string>

#include "render/isolated_read.h"
#include "render/vdb_read_here.h"

namespace {

bool writeAll(const std::string& s) {
  for (size_t at = 0; at < s.size();) {
    const ssize_t w = ::write(STDOUT_FILENO, s.data() + at, s.size() - at);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    at += size_t(w);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return 2;
  try {
    for (int i = 2; i < argc; ++i) {
      std::string record;
      morphoflow::putRecord(&record, morphoflow::vdbReaderAnswer(argv[1], argv[i]));
      if (!writeAll(record)) return 4;  // each answer goes as soon as it is known
    }
  } catch (const std::exception&) {
    return 3;
  }
  return 0;
}
