#include "core/parallel.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

namespace morphoflow {

ThreadLimit::ThreadLimit(int threads) {
  if (threads > 0)
    control_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     size_t(threads));
}
ThreadLimit::~ThreadLimit() = default;

int hardwareThreads() { return tbb::info::default_concurrency(); }

}  // namespace morphoflow
