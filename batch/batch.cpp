#include "batch/batch.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <list>
#include <map>
#include <regex>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "batch/batch_plan.h"
#include "batch/batch_summary.h"
#include "core/error.h"
#include "core/number_text.h"
#include "core/output_file.h"
#include "core/parallel.h"
#include "run/checkpoint.h"
#include "run/child_process.h"
#include "run/folder_lock.h"
#include "run/scene_hash.h"
#include "run/stop_signal.h"
#include "scenes/scene_loader.h"
#include "sim/scene_inputs.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

// A warning is shown even with --quiet.
void warnLine(const std::string& line) { std::cerr << line << "\n"; }

// What a run needs besides its plan: validated? resumable? already done?
struct Prepared {
  std::string hash;  // the scene's settings hash; empty when invalid
  bool resume = false;
};

// Runs the shard's part of a plan, each run a child process.
class BatchRunner {
 public:
  BatchRunner(BatchPlan plan, const BatchOptions& opt) : plan_(std::move(plan)), opt_(opt), dir_(opt.out) {
    if (dir_.empty()) throw UserError({"--out", 0, 0}, "", "no output folder given", "add --out DIR");
    const auto [i, n] = opt.shard.empty() ? std::pair{0, 1} : parseShard(opt.shard);
    for (size_t k = 0; k < plan_.runs.size(); ++k)
      if (int(k % size_t(n)) == i) {
        RunRecord r;
        r.run = plan_.runs[k];
        records_.push_back(std::move(r));
      }
  }

  int run() {
    validate();
    createOutputFolder(dir_);
    // one batch (or shard) at a time in a folder; its runs lock their own
    const FolderLock lock(
        dir_, opt_.shard.empty()
                  ? std::string(".morphoflow.lock")
                  : ".morphoflow-shard-" + std::regex_replace(opt_.shard, std::regex("/"), "-of-") + ".lock");
    checkBatchFolder(dir_, plan_);
    StopSignals signals;
    writeSummary();
    const int threads = std::max(1, hardwareThreads() / std::max(1, opt_.jobs));
    say(fmt::format("{}: {} runs, {} at a time with {} thread{} each -> {}", plan_.kind, records_.size(), opt_.jobs,
                    threads, threads == 1 ? "" : "s", dir_.string()));
    loop(threads);
    const int sig = StopSignals::received();
    for (RunRecord& r : records_)
      if (r.status == "pending") r.status = "not started";
    writeSummary();
    printSummary(std::cout, records_, dir_);
    if (plan_.kind == "sweep" && opt_.shard.empty() && !sig) writeSweepOutputs(dir_, plan_.keys, records_, warnLine);
    if (sig) say(fmt::format("stopped by {}; continue with --resume", sig == SIGINT ? "SIGINT" : "SIGTERM"));
    return sig ? 128 + sig : batchExitStatus(records_);
  }

 private:
  struct Running {
    size_t index;
    ChildProcess child;
    std::chrono::steady_clock::time_point started;
    fs::file_time_type startedFile;
  };

  // Every scene is loaded first; without --keep-going one bad scene stops the
  // batch before anything runs.
  void validate() {
    prepared_.resize(records_.size());
    std::vector<std::string> errors;
    for (size_t i = 0; i < records_.size(); ++i) {
      try {
        const Scene scene = loadScene(records_[i].run.scene, records_[i].run.overrides);
        checkSceneInputs(scene);
        prepared_[i].hash = sceneHash(scene);
      } catch (const UserError& e) {
        records_[i].status = "invalid";
        records_[i].exitCode = 2;
        const std::string& scene = records_[i].run.scene;
        records_[i].error = e.where().file == scene ? e.what() : scene + ": " + e.what();
        errors.push_back(records_[i].error);
      }
    }
    if (errors.empty() || opt_.keepGoing) return;
    std::vector<std::string> shown;  // a sweep's runs often share one error
    for (const std::string& e : errors)
      if (std::find(shown.begin(), shown.end(), e) == shown.end()) {
        std::cerr << e << "\n";
        shown.push_back(e);
      }
    throw UserError({plan_.kind, 0, 0}, "",
                    fmt::format("{} of {} runs are invalid; nothing was run", errors.size(), records_.size()),
                    "fix them, or add --keep-going to run the valid ones");
  }

  // --resume: a run completed with the same settings is skipped; one with
  // checkpoints and the same settings continues from them; any other runs afresh.
  bool skipOrResume(size_t i) {
    RunRecord& r = records_[i];
    const fs::path folder = dir_ / r.run.folder;
    if (!opt_.resume) return false;
    const nlohmann::json prev = readJsonFile(folder / "run.json");
    if (prev.is_object() && prev.value("exit_state", "") == "completed" &&
        prev.value("settings_hash", "") == prepared_[i].hash) {
      readRunFolder(dir_, fs::file_time_type::min(), &r);
      r.status = "skipped";
      r.exitCode = 0;
      r.wallSeconds = prev.value("wall_seconds", 0.0);
      return true;
    }
    // A run whose settings changed since (an edited scene, another --set) runs afresh.
    const bool sameSettings = !prev.is_object() || prev.value("settings_hash", "") == prepared_[i].hash;
    prepared_[i].resume = sameSettings && hasCheckpoint(folder);
    return false;
  }

  void start(size_t i, int threads, std::list<Running>* running) {
    RunRecord& r = records_[i];
    const fs::path folder = dir_ / r.run.folder;
    createOutputFolder(folder);
    const fs::path console = folder / "console.txt";
    std::error_code ec;
    if (!prepared_[i].resume) fs::remove(console, ec);  // a new run starts a new console log
    std::vector<std::string> args{"run", r.run.scene, "--out", folder.string(), "--threads", std::to_string(threads),
                                  "--quiet"};
    for (const std::string& s : r.run.overrides) args.insert(args.end(), {"--set", s});
    if (prepared_[i].resume) args.push_back("--resume");
    r.resumed = prepared_[i].resume;
    r.status = "running";
    const fs::file_time_type now = fs::file_time_type::clock::now();
    running->emplace_back(Running{i, ChildProcess(exe_, args, console), std::chrono::steady_clock::now(), now});
  }

  void finish(Running& run, const ChildExit& e) {
    RunRecord& r = records_[run.index];
    r.exitCode = e.code;
    r.signal = e.signal;
    r.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - run.started).count();
    readRunFolder(dir_, run.startedFile, &r);
    recordExit(dir_, &r);
    ++finished_;
    say(fmt::format("[{}/{}] {}: {} ({:.1f} s){}", finished_, records_.size(), r.run.folder, r.status, r.wallSeconds,
                    r.error.empty() || succeeded(r) ? "" : ": " + r.error));
    writeSummary();
  }

  void loop(int threads) {
    std::list<Running> running;  // a child process does not move
    size_t next = 0;
    bool forwarded = false;
    while (true) {
      const int sig = StopSignals::received();
      if (sig && !forwarded) {  // every running scene checkpoints and stops
        for (const Running& r : running) r.child.signal(sig);
        forwarded = true;
      }
      while (!sig && running.size() < size_t(opt_.jobs) && next < records_.size()) {
        const size_t i = next++;
        if (records_[i].status != "pending") continue;  // invalid (--keep-going)
        if (skipOrResume(i)) {
          ++finished_;
          say(fmt::format("[{}/{}] {}: skipped (completed with the same settings)", finished_, records_.size(),
                          records_[i].run.folder));
          continue;
        }
        start(i, threads, &running);
      }
      for (auto it = running.begin(); it != running.end();) {
        if (std::optional<ChildExit> e = it->child.poll()) {
          finish(*it, *e);
          it = running.erase(it);
        } else {
          ++it;
        }
      }
      if (running.empty() && (sig || next >= records_.size())) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

  void writeSummary() {
    writeFileAtomically(summaryPath(dir_, opt_.shard), summaryJson(plan_, records_, opt_.shard).dump(2) + "\n");
  }

  void say(const std::string& line) const {
    if (!opt_.quiet) std::cerr << line << "\n";
  }

  BatchPlan plan_;
  const BatchOptions& opt_;
  const fs::path dir_;
  const std::string exe_ = opt_.executable.empty() ? selfExecutable() : opt_.executable;
  std::vector<RunRecord> records_;
  std::vector<Prepared> prepared_;
  size_t finished_ = 0;
};

}  // namespace

namespace {

// DIR/batch.shard-I-of-N.json by I, all of one batch and all N present.
std::map<int, nlohmann::json> readShardSummaries(const std::string& dirText) {
  static const std::regex shardFile(R"(batch\.shard-(\d+)-of-(\d+)\.json)");
  std::map<int, nlohmann::json> shards;
  int count = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(dirText), ec)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (!std::regex_match(name, m, shardFile)) continue;
    std::error_code fec;
    if (!fs::is_regular_file(fs::symlink_status(e.path(), fec)))
      throw UserError({e.path().string(), 0, 0}, "", "not a batch summary: it is not a regular file", "remove it");
    const nlohmann::json j = readJsonFile(e.path());
    if (const std::string problem = summaryProblem(j, fs::path(dirText)); !problem.empty())
      throw UserError({e.path().string(), 0, 0}, "", "not a batch summary: " + problem,
                      "remove it, or run that shard again");
    const auto i = parseWhole(m[1]), n = parseWhole(m[2]);
    if (!i || !n || *n > 1000000 || *i >= *n)
      throw UserError({e.path().string(), 0, 0}, "", "not a shard's summary (I/N with I below N <= 1000000)",
                      "remove it");
    const nlohmann::json& other = shards.empty() ? j : shards.begin()->second;
    if (count && (*n != count || j["batch_id"] != other["batch_id"] || j["planned_runs"] != other["planned_runs"] ||
                  j["kind"] != other["kind"] ||
                  j.value("keys", nlohmann::json::array()) != other.value("keys", nlohmann::json::array())))
      throw UserError({e.path().string(), 0, 0}, "", "the shard summaries are from different batches",
                      "gather each batch's folder on its own");
    count = int(*n);
    shards[int(*i)] = j;
  }
  if (ec || shards.empty())
    throw UserError({dirText, 0, 0}, "", "no shard summaries (batch.shard-I-of-N.json) here",
                    "run the shards with --shard I/N --out " + dirText);
  std::vector<std::string> missing;
  for (int i = 0; i < count; ++i)
    if (!shards.count(i)) missing.push_back(std::to_string(i));
  if (!missing.empty())
    throw UserError({dirText, 0, 0}, "",
                    fmt::format("shards {} of {} have written no summary", fmt::join(missing, ", "), count),
                    "wait for them or run them again");
  return shards;
}

// Shard I holds runs I, I + N, I + 2N, ...: interleaved back into plan order.
std::vector<RunRecord> interleaveShards(const std::map<int, nlohmann::json>& shards, const std::string& dirText) {
  const size_t count = shards.size();
  std::vector<std::vector<RunRecord>> parts;
  size_t total = 0;
  for (const auto& [i, j] : shards) total += parts.emplace_back(recordsFromJson(j)).size();
  // Shard i of N holds the planned runs i, i + N, ...: every one of them, no more.
  const size_t planned = shards.begin()->second["planned_runs"].get<size_t>();
  for (const auto& [i, j] : shards)
    if (j["runs"].size() != (planned + count - 1 - size_t(i)) / count)
      throw UserError({dirText, 0, 0}, "",
                      fmt::format("shard {} of {} lists {} runs, where the plan of {} runs gives it {}", i, count,
                                  j["runs"].size(), planned, (planned + count - 1 - size_t(i)) / count),
                      "run that shard again");
  std::vector<RunRecord> records;
  for (size_t k = 0; k < total; ++k) {
    const auto& part = parts[k % count];
    if (k / count >= part.size())
      throw UserError({dirText, 0, 0}, "", "the shard summaries do not add up to one batch", "run the shards again");
    records.push_back(part[k / count]);
  }
  return records;
}

}  // namespace

int gatherBatch(const std::string& dirText) {
  const fs::path dir(dirText);
  const std::map<int, nlohmann::json> shards = readShardSummaries(dirText);
  const std::vector<RunRecord> records = interleaveShards(shards, dirText);
  const nlohmann::json& first = shards.begin()->second;
  BatchPlan plan;
  plan.kind = first.value("kind", "batch");
  plan.keys = first.value("keys", std::vector<std::string>{});
  plan.id = first.value("batch_id", "");
  for (const RunRecord& r : records) plan.runs.push_back(r.run);
  nlohmann::json merged = summaryJson(plan, records, "");
  merged["shards"] = shards.size();
  writeFileAtomically(dir / "batch.json", merged.dump(2) + "\n");
  printSummary(std::cout, records, dir);
  if (plan.kind == "sweep") writeSweepOutputs(dir, plan.keys, records, warnLine);
  return batchExitStatus(records);
}

int runBatch(const BatchOptions& opt) { return BatchRunner(planBatch(opt.scenes, opt.sets), opt).run(); }

int runSweep(const BatchOptions& opt) {
  std::vector<Vary> varies;
  for (const std::string& v : opt.varies) varies.push_back(parseVary(v));
  return BatchRunner(planSweep(opt.scenes.at(0), varies, opt.sets), opt).run();
}

}  // namespace morphoflow
