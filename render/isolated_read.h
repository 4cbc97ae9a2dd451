// Reading a file whose reader trusts what the file says, in a program of its
// own: `argv` runs as a new process (fork, then exec at once) and what it
// writes to its standard output comes back through a pipe; a reader that
// crashes, is killed or exits without a whole answer leaves this process
// unharmed and reports why. (OpenVDB 10 reads a block's stored length into
// its buffer before checking it against the buffer's size: a damaged .vdb can
// write past a buffer.) The reader runs none of this process's code after the
// fork, so it cannot wait on a lock that another thread held at the fork
// (OpenVDB's readers start TBB tasks; a run's TBB workers hold TBB's locks).
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

// How long the reader may take: `cpuSeconds` of processor time (a damaged
// file can send the reader round a loop for minutes) and `wallSeconds` in
// all (a reader that waits, using no processor time, is stopped too).
struct ReaderLimits {
  double cpuSeconds = 10.0;
  double wallSeconds = 60.0;
};
// The limits for a reader that may use `cpuSeconds`: ten times as long and a
// minute in all, for a busy machine and a slow file system.
inline ReaderLimits readerLimits(double cpuSeconds) { return {cpuSeconds, 60.0 + 10.0 * cpuSeconds}; }

// Runs the program argv[0] (a path) with `argv`, standard input and error on
// /dev/null. True when it exits with status 0: *out holds all it wrote.
// False and *error what became of it: *out then holds what it wrote before.
// The reader is killed when this process ends.
bool runIsolated(const std::vector<std::string>& argv, const ReaderLimits& limits, std::string* out,
                 std::string* error);

// Answers written by a reader as records: each a 64-bit length, then as many
// bytes. `putRecord` appends one to *s; `takeRecords` returns the whole ones.
void putRecord(std::string* s, const std::string& record);
std::vector<std::string> takeRecords(const std::string& s);

}  // namespace morphoflow
