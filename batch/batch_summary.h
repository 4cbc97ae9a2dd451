// A batch's summary: one record per run, printed as a table on stdout and
// kept as DIR/batch.json (a sharded run: DIR/batch.shard-I-of-N.json, merged
// by `morphoflow gather`); a sweep's sweep.csv and contact sheet.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "batch/batch_plan.h"

namespace morphoflow {

struct RunRecord {
  BatchRun run;
  std::string status = "pending";  // pending, running, completed, skipped, invalid, error, failed,
                                   // crashed, killed, interrupted, not started
  int exitCode = -1;
  int signal = 0;
  double wallSeconds = 0;
  long steps = 0, frames = 0;
  uintmax_t bytesWritten = 0;
  std::string error;
  std::string lastFrame;  // relative to the batch folder; empty when none
  bool resumed = false;
};

// A JSON file's contents when it is a regular file that parses, else null.
nlohmann::json readJsonFile(const std::filesystem::path& file);

bool succeeded(const RunRecord& r);
// 0, 2 (any user error), 1 (anything else not completed).
int batchExitStatus(const std::vector<RunRecord>& records);

// Fills a run's steps, frames, bytes, error and last frame from its folder
// (run.json only when written after `startedAt`, so a crash never reports an older run).
void readRunFolder(const std::filesystem::path& batchDir, std::filesystem::file_time_type startedAt, RunRecord* r);
// A finished child's status (and error, when run.json gave none) from its exit code and signal.
void recordExit(const std::filesystem::path& batchDir, RunRecord* r);

nlohmann::json summaryJson(const BatchPlan& plan, const std::vector<RunRecord>& records, const std::string& shard);
std::vector<RunRecord> recordsFromJson(const nlohmann::json& summary);
// What is wrong with a summary read back (its schema: every key gather reads,
// of its type; every path it names relative, inside `batchDir` and a regular
// file there), or "" when nothing is.
std::string summaryProblem(const nlohmann::json& summary, const std::filesystem::path& batchDir);
void printSummary(std::ostream& out, const std::vector<RunRecord>& records, const std::filesystem::path& batchDir);

// The summary file of a shard ("I/N"), or batch.json when not sharded.
std::filesystem::path summaryPath(const std::filesystem::path& dir, const std::string& shard);
// Refuses (UserError) a folder that holds the summary of another batch.
void checkBatchFolder(const std::filesystem::path& dir, const BatchPlan& plan);
// sweep.csv and contact_sheet.png from a complete sweep's records (at most
// kMaxSheetCells values a side on the sheet); a frame the sheet cannot show,
// or a sheet too large to draw, is reported through `warn`.
constexpr size_t kMaxSheetCells = 256;
void writeSweepOutputs(const std::filesystem::path& dir, const std::vector<std::string>& keys,
                       const std::vector<RunRecord>& records, const std::function<void(const std::string&)>& warn);

}  // namespace morphoflow
