// Parallel loops (TBB). Work is cut into chunks that do not depend on the
// thread count, and reductions sum per-chunk partials in a fixed order, so
// results are bitwise identical for any number of threads.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "core/vec.h"

#if defined(__SANITIZE_THREAD__)
#include <thread>
#endif

namespace morphoflow {

// Calls fn(i) for i in [0, n), in parallel, `grain` items per task.
template <typename Fn>
void parallelFor(size_t n, Fn&& fn, size_t grain = 1) {
  if (n == 0) return;
#if defined(__SANITIZE_THREAD__)
  // ThreadSanitizer builds (scripts/tsan): Debian's libtbb is not
  // instrumented, so TSan cannot see its task hand-offs. The same tasks run
  // instead on two plain threads, whose start and join TSan does see; races
  // between tasks, or with a concurrent loop, are then reported exactly.
  const size_t tasks = (n + grain - 1) / grain;
  auto run = [&](size_t first) {
    for (size_t k = first; k < tasks; k += 2)
      for (size_t i = k * grain; i < std::min(n, (k + 1) * grain); ++i) fn(i);
  };
  std::thread other(run, 1);
  run(0);
  other.join();
#else
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, n, grain),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) fn(i);
      },
      tbb::simple_partitioner());
#endif
}

// Calls fn(i) for i in [0, n) as tasks that run at once: pieces of work
// independent of one another, whose own parallel loops leave a thread idle
// at their serial parts. Each runs isolated: a thread that waits inside one
// of its loops takes only that loop's work, never another piece's, so what
// it keeps thread-local (rowScratch) stays its own.
template <typename Fn>
void parallelTasks(size_t n, Fn&& fn) {
#if defined(__SANITIZE_THREAD__)
  for (size_t i = 0; i < n; ++i) fn(i);  // (one after another: parallelFor's plain threads within each)
#else
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, n, 1),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) tbb::this_task_arena::isolate([&] { fn(i); });
      },
      tbb::simple_partitioner());
#endif
}

// Rows per task of a D-dim lattice: tasks of ~16k cells, fixed, independent
// of the thread count.
template <int D>
size_t rowGrain(const IVec<D>& dims) {
  return std::max<size_t>(1, 16384 / size_t(dims[0]));
}

// Calls fn(row) for each row of a D-dim lattice (a row = all x for fixed y[, z]);
// row r covers cells [r * nx, (r + 1) * nx).
template <int D, typename Fn>
void parallelForRows(const IVec<D>& dims, Fn&& fn) {
  size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= size_t(dims[a]);
  parallelFor(rows, fn, rowGrain<D>(dims));
}

// Calls fn(row, c) for every row, in parallel: c holds the coordinates of
// the row's first cell (x = 0).
template <int D, typename Fn>
void forEachRow(const IVec<D>& dims, Fn&& fn) {
  parallelForRows<D>(dims, [&](size_t row) {
    IVec<D> c(0);
    size_t rest = row;
    for (int a = 1; a < D; ++a) {
      c[a] = int(rest % size_t(dims[a]));
      rest /= size_t(dims[a]);
    }
    fn(row, c);
  });
}

// Calls fn(cell, index) for every cell, in parallel over rows.
template <int D, typename Fn>
void forEachCell(const IVec<D>& dims, Fn&& fn) {
  forEachRow<D>(dims, [&](size_t row, IVec<D> c) {
    size_t base = row * size_t(dims[0]);
    for (int x = 0; x < dims[0]; ++x) {
      c[0] = x;
      fn(c, base + size_t(x));
    }
  });
}

// Sum of f(i), i in [begin, end), in a fixed order: four running sums
// (i mod 4 relative to begin) added pairwise at the end, so the additions
// do not wait on one another (one running sum is bound by the add latency).
template <typename Fn>
double orderedSum(size_t begin, size_t end, Fn& f) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  size_t i = begin;
  for (; i + 4 <= end; i += 4) {
    s0 += f(i);
    s1 += f(i + 1);
    s2 += f(i + 2);
    s3 += f(i + 3);
  }
  for (; i < end; ++i) s0 += f(i);
  return (s0 + s1) + (s2 + s3);
}

// The sum of chunkSum(begin, end) over fixed chunks [begin, end) of [0, n),
// in parallel, the partials summed in order.
template <typename ChunkSum>
double deterministicChunkSum(size_t n, ChunkSum&& chunkSum) {
  constexpr size_t kChunk = 8192;
  size_t chunks = (n + kChunk - 1) / kChunk;
  if (chunks <= 1) return chunkSum(size_t(0), n);
  std::vector<double> partial(chunks, 0.0);
  parallelFor(chunks, [&](size_t k) { partial[k] = chunkSum(k * kChunk, std::min(n, (k + 1) * kChunk)); });
  double s = 0;
  for (double p : partial) s += p;
  return s;
}

// Deterministic sum of f(i), i in [0, n): fixed chunks, partials summed in order.
template <typename Fn>
double deterministicSum(size_t n, Fn&& f) {
  return deterministicChunkSum(n, [&](size_t begin, size_t end) { return orderedSum(begin, end, f); });
}

// Deterministic sum of fn(row) over the rows of a lattice: the rows are cut
// into fixed groups (as parallelForRows), partials summed in order.
template <int D, typename Fn>
double deterministicRowSum(const IVec<D>& dims, Fn&& fn) {
  size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= size_t(dims[a]);
  const size_t grain = rowGrain<D>(dims);
  const size_t groups = (rows + grain - 1) / grain;
  std::vector<double> partial(groups, 0.0);
  parallelFor(groups, [&](size_t g) {
    double s = 0;
    for (size_t r = g * grain; r < std::min(rows, (g + 1) * grain); ++r) s += fn(r);
    partial[g] = s;
  });
  double s = 0;
  for (double p : partial) s += p;
  return s;
}

// Deterministic maximum of f(i).
template <typename Fn>
double deterministicMax(size_t n, Fn&& f, double init = 0.0) {
  constexpr size_t kChunk = 8192;
  size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<double> partial(std::max<size_t>(chunks, 1), init);
  parallelFor(chunks, [&](size_t k) {
    double m = init;
    size_t end = std::min(n, (k + 1) * kChunk);
    for (size_t i = k * kChunk; i < end; ++i) m = std::max(m, double(f(i)));
    partial[k] = m;
  });
  double m = init;
  for (double p : partial) m = std::max(m, p);
  return m;
}

// Limits TBB to `threads` worker threads while alive (0 = all cores).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  std::unique_ptr<tbb::global_control> control_;
};

int hardwareThreads();

}  // namespace morphoflow
