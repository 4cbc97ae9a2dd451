// WorkPool: the stages' vectors circulate without new allocations;
// AtomicFile leaves either the whole file or nothing; RowField stores a
// field's distinct rows once.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "core/laplace_system.h"
#include "core/output_file.h"
#include "core/parallel.h"
#include "core/row_field.h"
#include "core/work_pool.h"

namespace morphoflow {
namespace {

namespace fs = std::filesystem;

TEST(WorkPool, LendsTheLargestVectorAndKeepsItsStorage) {
  WorkPool pool;
  std::vector<double> a(1000), b(10);
  const double* storage = a.data();
  pool.give(&a);
  pool.give(&b);
  EXPECT_EQ(a.capacity(), 0u);  // given away
  std::vector<double> c;
  pool.lend(&c);
  EXPECT_EQ(c.data(), storage);  // the largest, the same storage
  c.resize(900);                 // within its capacity: no allocation
  EXPECT_EQ(c.data(), storage);
  std::vector<double> d(5, 1.0);
  pool.lend(&d);  // a vector with storage keeps it
  EXPECT_EQ(d.size(), 5u);
  std::vector<float> f;
  pool.lend(&f);  // the pools of the two precisions are apart
  EXPECT_EQ(f.capacity(), 0u);
  std::vector<double> e;
  pool.lend(&e);
  EXPECT_EQ(e.capacity(), 10u);
  pool.lend(&e);
  std::vector<double> none;
  pool.lend(&none);
  EXPECT_EQ(none.capacity(), 0u);  // the pool is empty now
}

// Float arrays live in the pool's double vectors, two to a vector where they
// fit, and go back to it unchanged: a float stage costs the pool nothing.
TEST(WorkPool, FloatArraysLiveInTheDoubleVectors) {
  WorkPool pool;
  std::vector<double> a(1000), b(1000);
  const double *sa = a.data(), *sb = b.data();
  pool.give(&a);
  pool.give(&b);
  const size_t held = pool.bytes();
  {
    FloatArrays f;
    f.lend(&pool, 3, 1000);  // 500 doubles' bytes each
    ASSERT_EQ(f.size(), 3u);
    EXPECT_EQ(static_cast<void*>(f[0]), static_cast<const void*>(sa));  // two in the larger vector
    EXPECT_EQ(f[1], f[0] + 1000);
    EXPECT_EQ(static_cast<void*>(f[2]), static_cast<const void*>(sb));  // one in the other
    EXPECT_EQ(pool.bytes(), 0u);
    for (size_t k = 0; k < 3; ++k)
      for (size_t i = 0; i < 1000; ++i) f[k][i] = float(k * 1000 + i);
    for (size_t k = 0; k < 3; ++k) EXPECT_EQ(f[k][999], float(k * 1000 + 999));  // no overlap
    f.give(&pool);
    EXPECT_EQ(pool.bytes(), held);
    // Floats first: a float vector large enough serves whole.
    std::vector<float> g(1000);
    const float* sg = g.data();
    pool.give(&g);
    f.lend(&pool, 2, 1000, FloatArrays::First::Floats);
    EXPECT_EQ(f[0], sg);
    EXPECT_EQ(static_cast<void*>(f[1]), static_cast<const void*>(sa));
  }  // (given back to nobody: freed)
  // An empty pool makes new double vectors, kept by the pool once given.
  WorkPool empty;
  FloatArrays f;
  f.lend(&empty, 3, 100);
  EXPECT_EQ(f.size(), 3u);
  f.give(&empty);
  EXPECT_GE(empty.bytes(), 3u * 100u * sizeof(float));
  EXPECT_LE(empty.bytes(), 4u * 100u * sizeof(float));
}

// No pooled vector holds more than the largest size given back: a resize
// past the capacity (which doubles it) is trimmed when given back;
// resizeExactly grows to the size.
TEST(WorkPool, VectorsHoldTheLargestSizeNotADoubledOne) {
  WorkPool pool;
  std::vector<double> v(100);
  v.resize(150);  // (doubled)
  EXPECT_GE(v.capacity(), 200u);
  pool.give(&v);
  EXPECT_EQ(pool.bytes(), 150u * sizeof(double));
  std::vector<double> a;
  pool.lend(&a);
  EXPECT_EQ(a.capacity(), 150u);
  a.resize(100);
  pool.give(&a);  // (a stage that needed less)
  EXPECT_EQ(pool.bytes(), 150u * sizeof(double));
  std::vector<float> w(10);
  resizeExactly(&w, 11, 1.0f);
  EXPECT_EQ(w.capacity(), 11u);
  EXPECT_EQ(w[10], 1.0f);
}

TEST(AtomicFile, WritesPiecesAndLeavesNothingWithoutCommit) {
  const fs::path dir = fs::temp_directory_path() / ("mf_atomic_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    AtomicFile f(dir / "whole.bin");
    f.write("abc", 3);
    f.write("def", 3);
    EXPECT_FALSE(fs::exists(dir / "whole.bin"));  // not before commit
    f.commit();
  }
  std::ifstream in(dir / "whole.bin");
  std::string text;
  in >> text;
  EXPECT_EQ(text, "abcdef");
  {
    AtomicFile f(dir / "abandoned.bin");
    f.write("x", 1);
  }  // destroyed without commit: an error on the way
  EXPECT_FALSE(fs::exists(dir / "abandoned.bin"));
  EXPECT_FALSE(fs::exists(dir / "abandoned.bin.tmp"));
  fs::remove_all(dir);
}

// A field's rows are kept once per distinct content: the values read back
// are the dense ones, writing needs densify(), and a box's Laplacian keeps a
// handful of rows however fine the grid, its diagonal the count of open faces.
TEST(RowField, KeepsDistinctRowsAndReadsBackTheDenseValues) {
  const IVec<3> dims(12, 7, 5);
  RowField<3> f(dims, 0.0f);
  forEachCell<3>(dims, [&](const IVec<3>& k, size_t i) { f.at(i) = float(k[0] == 0) + 2.0f * float(k[1] == 6); });
  const std::vector<float> dense = f.expanded();
  f.compact();
  EXPECT_EQ(f.storedRows(), 2u);  // rows with y < 6 and rows with y = 6
  EXPECT_EQ(f.expanded(), dense);
  for (size_t i = 0; i < f.size(); ++i) ASSERT_EQ(f[i], dense[i]) << i;
  EXPECT_THROW(f.at(0) = 1.0f, std::logic_error);
  f.densify();
  f.at(3) = 5.0f;
  EXPECT_EQ(f[3], 5.0f);

  for (int n : {16, 48}) {
    const LaplaceSystem<3> A = makeNeumannLaplacian<3>(IVec<3>(n), {}, 1.0);
    for (int a = 0; a < 3; ++a) EXPECT_LE(A.w[a].storedRows(), 2u) << "axis " << a;
    EXPECT_LE(A.diag.storedRows(), 9u);
    forEachCell<3>(A.dims, [&](const IVec<3>& k, size_t i) {
      int open = 0;
      for (int a = 0; a < 3; ++a) open += (k[a] > 0) + (k[a] < n - 1);
      ASSERT_EQ(A.diag[i], float(open)) << k[0] << " " << k[1] << " " << k[2];
    });
  }
}

// A compact field's rows written again (a moving obstacle's few rows) read
// back as the dense field written the same way; a row that comes out as it
// was keeps its stored row, equal new rows share one, and rows no row uses
// any more do not pile up over many rewrites.
TEST(RowField, RowsWrittenAgainReadAsTheDenseFieldAndStayCompact) {
  const IVec<3> dims(16, 12, 10);
  RowField<3> f(dims, 1.0f), g(dims, 2.0f);
  RowField<3> dense(dims, 1.0f), denseG(dims, 2.0f);
  f.compact();
  g.compact();
  for (int step = 0; step < 40; ++step) {
    // a ball of radius 3 moving along x, y and z: its rows, its cells set to 0 (f) and to their x (g)
    const IVec<3> was(3 + (step + 9) % 10, 3 + (step + 5) % 6, 3 + (step + 3) % 4);
    const IVec<3> centre(3 + step % 10, 3 + step % 6, 3 + step % 4);
    IVec<3> lo, hi;  // the cells that held or hold it
    for (int a = 0; a < 3; ++a) lo[a] = std::min(was[a], centre[a]) - 3, hi[a] = std::max(was[a], centre[a]) + 4;
    auto write = [&](size_t r, const std::array<float*, 2>& v) {
      IVec<3> k = latticeCoord<3>(dims, r * size_t(dims[0]));
      for (k[0] = lo[0]; k[0] < hi[0]; ++k[0]) {
        const IVec<3> d = k - centre;
        const bool inside = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= 9;
        v[0][k[0]] = inside ? 0.0f : 1.0f;
        v[1][k[0]] = inside ? float(k[0]) : 2.0f;
      }
    };
    const std::vector<size_t> rows = rowsOf<3>(dims, lo, hi);
    rewriteRows<3, 2>({&f, &g}, rows, write);
    rewriteRows<3, 2>({&dense, &denseG}, rows, write);
    ASSERT_EQ(f.expanded(), dense.expanded()) << "step " << step;
    ASSERT_EQ(g.expanded(), denseG.expanded()) << "step " << step;
    const auto [r0, r1] = rowSpan(rows);  // the rows a GPU upload takes again
    const std::vector<float> all = f.expanded();
    ASSERT_EQ(f.expandedRows(r0, r1),
              std::vector<float>(all.begin() + ptrdiff_t(r0 * 16), all.begin() + ptrdiff_t(r1 * 16)));
    EXPECT_FALSE(f.dense());
    // in use: at most the ball's 49 rows and the uniform row; unused ones are
    // dropped before they outnumber them, with one step's new rows on top
    EXPECT_LE(f.storedRows(), 2u * 50u + 49u) << "step " << step;
  }
  // A rewrite that changes nothing keeps every stored row.
  const size_t stored = f.storedRows();
  rewriteRows<3, 1>({&f}, rowsOf<3>(dims, IVec<3>(0), dims), [](size_t, const std::array<float*, 1>&) {});
  EXPECT_EQ(f.storedRows(), stored);
  EXPECT_TRUE(rowsOf<3>(dims, IVec<3>(2), IVec<3>(2)).empty());
}

}  // namespace
}  // namespace morphoflow
