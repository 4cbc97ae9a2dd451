#include "batch/batch_summary.h"

#include <algorithm>
#include <csignal>
#include <fstream>
#include <map>
#include <regex>

#include <fmt/format.h>

#include "run/child_process.h"
#include "run/memory_estimate.h"
#include "run/version.h"
#include "core/error.h"
#include "core/output_file.h"
#include "render/contact_sheet.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

// The newest frame image of a run folder, relative to the batch folder.
std::string lastFrame(const fs::path& batchDir, const std::string& folder) {
  std::error_code ec;
  std::string best;
  static const std::regex frame(R"(\d{6}\.(png|exr))");
  for (const auto& e : fs::directory_iterator(batchDir / folder / "frames", ec)) {
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, frame) && name > fs::path(best).filename().string())
      best = (fs::path(folder) / "frames" / name).string();
  }
  return best;
}

// The last line of the child's console output, for a run that left no error in run.json.
std::string lastLine(const fs::path& file) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

nlohmann::json readJsonFile(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(file, ec))) return nullptr;  // never a pipe or device
  std::ifstream in(file);
  return nlohmann::json::parse(in, nullptr, false);
}

bool succeeded(const RunRecord& r) { return r.status == "completed" || r.status == "skipped"; }

int batchExitStatus(const std::vector<RunRecord>& records) {
  int worst = 0;
  for (const RunRecord& r : records) {
    if (r.status == "invalid" || r.status == "error") return 2;
    if (!succeeded(r)) worst = 1;
  }
  return worst;
}

void readRunFolder(const fs::path& batchDir, fs::file_time_type startedAt, RunRecord* r) {
  const fs::path runJson = batchDir / r->run.folder / "run.json";
  std::error_code ec;
  const bool fresh = fs::last_write_time(runJson, ec) >= startedAt && !ec;
  const nlohmann::json j = fresh ? readJsonFile(runJson) : nlohmann::json();
  if (j.is_object()) {
    r->steps = j.value("steps", 0L);
    r->frames = j.value("frames_written", 0L);
    r->bytesWritten = 0;
    if (j.contains("bytes_written"))
      for (const auto& [kind, bytes] : j["bytes_written"].items())
        if (bytes.is_number_unsigned()) r->bytesWritten += bytes.get<uintmax_t>();
    r->error = j.value("error", "");
  }
  r->lastFrame = lastFrame(batchDir, r->run.folder);
}

void recordExit(const fs::path& batchDir, RunRecord* r) {
  // A child stopped by SIGINT or SIGTERM before its run loop started dies of it: it too is interrupted.
  if (r->signal == SIGINT || r->signal == SIGTERM) r->status = "interrupted";
  else if (r->signal != 0) r->status = r->signal == SIGKILL ? "killed" : "crashed";
  else if (r->exitCode == 0) r->status = "completed";
  else if (r->exitCode == 2) r->status = "error";
  else if (r->exitCode == 128 + SIGINT || r->exitCode == 128 + SIGTERM) r->status = "interrupted";
  else r->status = "failed";
  if (r->signal != 0 && r->status != "interrupted")
    r->error =
        "killed by " + signalName(r->signal) + (r->signal == SIGKILL ? " (the out-of-memory killer, or kill -9)" : "");
  else if (r->exitCode != 0 && r->error.empty())
    r->error = lastLine(batchDir / r->run.folder / "console.txt");
}

nlohmann::json summaryJson(const BatchPlan& plan, const std::vector<RunRecord>& records, const std::string& shard) {
  nlohmann::json runs = nlohmann::json::array();
  for (const RunRecord& r : records) {
    nlohmann::json j = {{"scene", r.run.scene},   {"folder", r.run.folder},         {"overrides", r.run.overrides},
                        {"status", r.status},     {"exit_code", r.exitCode},        {"wall_seconds", r.wallSeconds},
                        {"steps", r.steps},       {"frames", r.frames},             {"bytes_written", r.bytesWritten},
                        {"resumed", r.resumed},   {"last_frame", r.lastFrame}};
    if (r.signal) j["signal"] = signalName(r.signal);
    if (!r.error.empty()) j["error"] = r.error;
    if (!r.run.labels.empty()) {
      nlohmann::json values;
      for (size_t k = 0; k < plan.keys.size(); ++k) values[plan.keys[k]] = r.run.labels[k];
      j["values"] = values;
    }
    runs.push_back(std::move(j));
  }
  return {{"version", kVersion}, {"kind", plan.kind},       {"batch_id", plan.id},
          {"keys", plan.keys},   {"planned_runs", plan.runs.size()}, {"shard", shard.empty() ? "0/1" : shard},
          {"exit_status", batchExitStatus(records)}, {"runs", runs}};
}

namespace {

// A path a summary names: relative, no "..", and (when `file`) a regular file inside the folder.
// A folder linked out of the batch folder is outside it too.
bool insideFolder(const std::string& path, const fs::path& batchDir, bool file) {
  const fs::path p(path);
  if (path.empty() || p.is_absolute()) return false;
  for (const fs::path& part : p)
    if (part == "..") return false;
  if (!file) return true;
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(batchDir / p, ec))) return false;
  const fs::path root = fs::canonical(batchDir, ec), at = fs::canonical(batchDir / p, ec);
  if (ec) return false;
  const auto [end, _] = std::mismatch(root.begin(), root.end(), at.begin(), at.end());
  return end == root.end();
}

}  // namespace

std::string summaryProblem(const nlohmann::json& j, const fs::path& batchDir) {
  using json = nlohmann::json;
  if (!j.is_object()) return "it is not a JSON object";
  auto is = [](const json& o, const char* key, bool (json::*test)() const noexcept) {
    return o.contains(key) && (o[key].*test)();
  };
  if (!is(j, "runs", &json::is_array)) return "it has no list of runs";
  if (!is(j, "planned_runs", &json::is_number_unsigned)) return "it has no planned_runs count";
  if (!is(j, "kind", &json::is_string) || !is(j, "batch_id", &json::is_string)) return "it lacks its kind or batch_id";
  if (j["kind"] != "batch" && j["kind"] != "sweep") return "its kind is neither batch nor sweep";
  if (j.contains("keys") && !(j["keys"].is_array() && std::all_of(j["keys"].begin(), j["keys"].end(),
                                                                  [](const json& k) { return k.is_string(); })))
    return "its keys are not a list of names";
  if (j["kind"] == "sweep" && (!j.contains("keys") || j["keys"].empty()))
    return "it is a sweep's without the keys it varies";
  for (size_t k = 0; k < j["runs"].size(); ++k) {
    const json& r = j["runs"][k];
    const std::string at = "run " + std::to_string(k) + " ";
    if (!r.is_object()) return at + "is not an object";
    for (const char* key : {"scene", "folder", "status", "last_frame"})
      if (!is(r, key, &json::is_string)) return at + "lacks the text '" + key + "'";
    for (const char* key : {"steps", "frames", "bytes_written"})
      if (!is(r, key, &json::is_number_unsigned)) return at + "lacks the count '" + key + "' (a whole number >= 0)";
    if (!is(r, "exit_code", &json::is_number_integer)) return at + "lacks its exit_code";
    if (!is(r, "wall_seconds", &json::is_number) || r["wall_seconds"].get<double>() < 0)
      return at + "lacks its wall_seconds";
    if (!is(r, "resumed", &json::is_boolean)) return at + "lacks 'resumed'";
    if (!is(r, "overrides", &json::is_array)) return at + "lacks its overrides";
    for (const json& o : r["overrides"])
      if (!o.is_string()) return at + "has an override that is not text";
    if (r.contains("values") && !r["values"].is_object()) return at + "has values that are not a table";
    if (r.contains("values"))
      for (const auto& [key, v] : r["values"].items())
        if (!v.is_string()) return at + "has a value of '" + key + "' that is not text";
    if (r.contains("error") && !r["error"].is_string()) return at + "has an error that is not text";
    if (!insideFolder(r["folder"].get<std::string>(), batchDir, false))
      return at + "names a folder outside the batch folder";
    const std::string last = r["last_frame"].get<std::string>();
    if (!last.empty() && !insideFolder(last, batchDir, true))
      return at + "names a last frame (" + last + ") that is not a file inside the batch folder";
  }
  return "";
}

std::vector<RunRecord> recordsFromJson(const nlohmann::json& summary) {
  std::vector<RunRecord> out;
  const std::vector<std::string> keys = summary.value("keys", std::vector<std::string>{});
  for (const auto& j : summary.at("runs")) {
    RunRecord r;
    r.run.scene = j.value("scene", "");
    r.run.folder = j.value("folder", "");
    r.run.overrides = j.value("overrides", std::vector<std::string>{});
    for (const std::string& k : keys) r.run.labels.push_back(j.contains("values") ? j["values"].value(k, "") : "");
    r.status = j.value("status", "");
    r.exitCode = j.value("exit_code", -1);
    r.wallSeconds = j.value("wall_seconds", 0.0);
    r.steps = j.value("steps", 0L);
    r.frames = j.value("frames", 0L);
    r.bytesWritten = j.value("bytes_written", uintmax_t(0));
    r.resumed = j.value("resumed", false);
    r.lastFrame = j.value("last_frame", "");
    r.error = j.value("error", "");
    out.push_back(std::move(r));
  }
  return out;
}

void printSummary(std::ostream& out, const std::vector<RunRecord>& records, const fs::path& batchDir) {
  size_t w = 5;
  for (const RunRecord& r : records) w = std::max(w, fs::path(r.run.scene).filename().string().size());
  size_t fw = 6;
  for (const RunRecord& r : records) fw = std::max(fw, r.run.folder.size());
  out << fmt::format("{:<{}}  {:<11} {:>4} {:>9} {:>8} {:>6} {:>10}  {:<{}}\n", "scene", w, "status", "exit", "wall",
                     "steps", "frames", "written", "folder", fw);
  int done = 0;
  for (const RunRecord& r : records) {
    done += succeeded(r);
    out << fmt::format("{:<{}}  {:<11} {:>4} {:>8.1f}s {:>8} {:>6} {:>10}  {}\n",
                       fs::path(r.run.scene).filename().string(), w, r.status,
                       r.exitCode < 0 ? std::string("-") : std::to_string(r.exitCode), r.wallSeconds, r.steps, r.frames,
                       humanBytes(r.bytesWritten), (batchDir / r.run.folder).string());
  }
  out << fmt::format("{} of {} runs completed\n", done, records.size());
  for (const RunRecord& r : records)
    if (!succeeded(r) && !r.error.empty()) out << fmt::format("{}: {}: {}\n", r.run.folder, r.status, r.error);
}

fs::path summaryPath(const fs::path& dir, const std::string& shard) {
  if (shard.empty()) return dir / "batch.json";
  const size_t slash = shard.find('/');
  return dir / fmt::format("batch.shard-{}-of-{}.json", shard.substr(0, slash), shard.substr(slash + 1));
}

void checkBatchFolder(const fs::path& dir, const BatchPlan& plan) {
  std::error_code ec;
  static const std::regex summary(R"(batch(\.shard-\d+-of-\d+)?\.json)");
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!std::regex_match(e.path().filename().string(), summary)) continue;
    const nlohmann::json j = readJsonFile(e.path());
    if (j.is_object() && j.value("batch_id", "") == plan.id) continue;
    throw UserError({e.path().string(), 0, 0}, "",
                    "the folder already holds another batch's outputs (other scenes, settings or values)",
                    "choose another --out, or remove the folder");
  }
}

void writeSweepOutputs(const fs::path& dir, const std::vector<std::string>& keys, const std::vector<RunRecord>& records,
                       const std::function<void(const std::string&)>& warn) {
  std::string csv;
  for (const std::string& k : keys) csv += csvField(k) + ",";
  csv += "status,exit_code,wall_seconds,last_frame\n";
  for (const RunRecord& r : records) {
    for (const std::string& l : r.run.labels) csv += csvField(l) + ",";
    csv += fmt::format("{},{},{:.3f},{}\n", r.status, r.exitCode, r.wallSeconds, csvField(r.lastFrame));
  }
  writeFileAtomically(dir / "sweep.csv", csv);

  // Columns by the first key, rows by the rest, in the order of the values.
  ContactSheet sheet;
  std::map<std::string, size_t> col, row;
  std::vector<std::pair<size_t, size_t>> at;
  for (const RunRecord& r : records) {
    std::string rowLabel;
    for (size_t k = 1; k < keys.size(); ++k) rowLabel += (k > 1 ? ", " : "") + r.run.labels[k];
    const std::string colLabel = r.run.labels[0];
    if (col.emplace(colLabel, sheet.columns.size()).second) sheet.columns.push_back(colLabel);
    if (row.emplace(rowLabel, sheet.rows.size()).second) sheet.rows.push_back(rowLabel);
    at.emplace_back(row[rowLabel], col[colLabel]);
  }
  sheet.images.assign(sheet.rows.size() * sheet.columns.size(), "");
  for (size_t i = 0; i < records.size(); ++i)
    if (!records[i].lastFrame.empty() && fs::path(records[i].lastFrame).extension() == ".png")
      sheet.images[at[i].first * sheet.columns.size() + at[i].second] = (dir / records[i].lastFrame).string();
  sheet.title = "columns: " + keys[0] + (keys.size() > 1 ? "    rows: " + keys[1] : "");
  for (size_t k = 2; k < keys.size(); ++k) sheet.title += ", " + keys[k];
  // Cells shrink so that the sheet stays within about 4096 pixels a side.
  const size_t most = std::max(sheet.columns.size(), sheet.rows.size());
  if (most > kMaxSheetCells) {
    warn(fmt::format("warning: no contact sheet: {} values a side, more than the {} one sheet shows", most,
                     kMaxSheetCells));
    return;
  }
  sheet.cellWidth = int(std::clamp<size_t>(4096 / most, 16, 160));
  for (const std::string& frame : writeContactSheet((dir / "contact_sheet.png").string(), sheet))
    warn("warning: the contact sheet shows a grey cell for " + frame);
}

}  // namespace morphoflow
