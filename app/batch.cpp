#include "app/batch.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include <fmt/format.h>

#include "app/run_options.h"
#include "core/error.h"
#include "scenes/scene_loader.h"

namespace fs = std::filesystem;

namespace morphoflow {

int runBatch(const BatchOptions& b) {
  int shardI = 0, shardN = 1;
  if (!b.shard.empty() && (std::sscanf(b.shard.c_str(), "%d/%d", &shardI, &shardN) != 2 || shardN < 1 ||
                           shardI < 0 || shardI >= shardN))
    throw UserError({"--shard", 0, 0}, "", "expected I/N with 0 <= I < N, got '" + b.shard + "'");
  // Check every scene first: a batch fails fast, before any simulation.
  std::vector<std::string> mine;
  for (size_t i = 0; i < b.scenes.size(); ++i)
    if (int(i % size_t(shardN)) == shardI) {
      loadScene(b.scenes[i]);
      mine.push_back(b.scenes[i]);
    }
  std::vector<int> status(mine.size(), 0);
  std::vector<std::string> errors(mine.size());
  auto work = [&](size_t i) {
    RunOptions o;
    o.scene = mine[i];
    o.out = (fs::path(b.out) / fs::path(mine[i]).stem()).string();
    o.quiet = true;
    try {
      status[i] = runScene(o);
    } catch (const std::exception& e) {
      errors[i] = e.what();
      status[i] = dynamic_cast<const UserError*>(&e) ? 2 : 1;
    }
  };
  for (size_t start = 0; start < mine.size(); start += size_t(b.jobs)) {
    std::vector<std::thread> pool;
    for (size_t i = start; i < std::min(mine.size(), start + size_t(b.jobs)); ++i) pool.emplace_back(work, i);
    for (auto& t : pool) t.join();
  }
  int worst = 0;
  for (size_t i = 0; i < mine.size(); ++i) {
    std::cerr << fmt::format("{}: {}\n", mine[i], status[i] == 0 ? "ok" : errors[i]);
    worst = std::max(worst, status[i]);
  }
  return worst;
}

}  // namespace morphoflow
