// The memory this process may still take, and byte counts in words.
#pragma once

#include <cstdint>
#include <string>

namespace morphoflow {

// Memory available to this process now: MemAvailable, capped by a cgroup
// limit and by what ulimit -v and -d leave it.
uintmax_t availableBytes();
// "1.23 GiB", "456 MiB".
std::string humanBytes(uintmax_t bytes);

}  // namespace morphoflow
