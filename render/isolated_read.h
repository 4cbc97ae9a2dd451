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

// True and *result the child's bytes; false and *error what became of it.
// The child may use `cpuSeconds` of processor time (a damaged file can also
// send the reader round a loop for minutes).
bool runIsolated(const std::function<std::string()>& work, double cpuSeconds, std::string* result, std::string* error);

}  // namespace morphoflow
