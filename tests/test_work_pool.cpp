// WorkPool: the stages' vectors circulate without new allocations, and
// AtomicFile leaves either the whole file or nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "core/output_file.h"
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

}  // namespace
}  // namespace morphoflow
