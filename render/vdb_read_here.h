// What the VDB reader (the program morphoflow-vdb-reader, render/isolated_read.h)
// does with one file, in its own process: opening a damaged file reads its
// grids' topology, which OpenVDB misreads. Modes:
// - "velocity": the file's velocity (render/velocity_answer.h);
// - "time": "1" and the `time` metadata's 8 bytes, "0" (none), or "E" and the error;
// - "summary": "N", the grids' names each ended by a newline, a NUL, the
//   domain_size metadata's 3 doubles, then the `density` grid's active
//   values as floats; or "E" and the error.
#pragma once

#include <string>

namespace morphoflow {

// The answer for `path`; an unknown mode is std::invalid_argument.
std::string vdbReaderAnswer(const std::string& mode, const std::string& path);

}  // namespace morphoflow
