// Reading a file whose reader trusts what the file says, in a child
// process: `work` runs in a fork of this process and its result (bytes)
// comes back through a pipe; a child that crashes, is killed or exits
// without a whole result leaves this process unharmed and reports why.
// (OpenVDB 10 reads a block's stored length into its buffer before checking
// it against the buffer's size: a damaged .vdb can write past a buffer.)
// `work` must not start threads (the child has only the forking one).
#pragma once

#include <functional>
#include <string>

namespace morphoflow {

// How long the child may take: `cpuSeconds` of processor time (a damaged
// file can send the reader round a loop for minutes) and `wallSeconds` in
// all (a child that waits, using no processor time, is stopped too).
struct ReaderLimits {
  double cpuSeconds = 10.0;
  double wallSeconds = 60.0;
};
// The limits for a reader that may use `cpuSeconds`: ten times as long and a
// minute in all, for a busy machine and a slow file system.
inline ReaderLimits readerLimits(double cpuSeconds) { return {cpuSeconds, 60.0 + 10.0 * cpuSeconds}; }

// True and *result the child's bytes; false and *error what became of it.
// The child is killed when this process ends.
bool runIsolated(const std::function<std::string()>& work, const ReaderLimits& limits, std::string* result,
                 std::string* error);

}  // namespace morphoflow
