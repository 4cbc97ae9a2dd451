// A bound on each allocation while a third-party reader parses a file the
// user gave. OpenVDB's reader sizes its buffers from lengths stored in the
// file (a metadata string, a Blosc block): a 10 KB file can claim terabytes,
// which is bad_alloc at best and, below the machine's memory, gigabytes
// touched before the read fails. Inside an AllocationLimit's scope, on its
// thread, a single request above the bound throws std::bad_alloc at once.
#pragma once

#include <cstddef>

namespace morphoflow {

class AllocationLimit {
 public:
  explicit AllocationLimit(size_t maxBytes);
  ~AllocationLimit();
  AllocationLimit(const AllocationLimit&) = delete;
  AllocationLimit& operator=(const AllocationLimit&) = delete;

 private:
  size_t previous_;
};

}  // namespace morphoflow
