// `morphoflow batch`, `sweep` and `gather`: each run in its own process (a
// crash or a kill -9 in one never stops the others), the summary on stdout
// and in batch.json checked against the run folders themselves, --set for
// every run, --keep-going, --resume, SIGINT, shards, the sweep's folders,
// sweep.csv and contact sheet, and the bad options.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <functional>

#include <csignal>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "render/image_io.h"
#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

// A small Gray-Scott scene (Pearson's square), `steps` long, a frame every `every`.
fs::path writeScene(const fs::path& dir, const std::string& name, long steps, long every,
                    const std::string& extra = "") {
  const fs::path p = dir / (name + ".toml");
  std::ofstream(p) << "name = \"" << name << "\"\n[grid]\nresolution = [40, 40]\n[domain]\nsize = [0.5, 0.5]\n"
                   << "[time]\ndt = 1.0\nsteps = " << steps
                   << "\n[rd]\nmodel = \"gray-scott\"\nintegrator = \"kim-lin\"\n"
                   << "boundary = \"periodic\"\ndiffusion = [2e-5, 1e-5]\n[rd.parameters]\nF = 0.04\nk = 0.06\n"
                   << "[rd.initial]\nvalues = [1.0, 0.0]\nsquare = 0.1\nsquare_values = [0.5, 0.25]\n"
                   << "[output]\nevery = " << every << "\nfield = \"v\"\nimage_size = 64\n"
                   << extra;
  return p;
}

nlohmann::json readJson(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

int countFiles(const fs::path& dir) {
  int n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) n += e.is_regular_file();
  return n;
}

const nlohmann::json& runNamed(const nlohmann::json& summary, const std::string& folder) {
  for (const auto& r : summary["runs"])
    if (r["folder"] == folder) return r;
  throw std::runtime_error("no run " + folder);
}

// The batch's child running `scene` (`morphoflow run SCENE ...`, by its
// command line: a child not yet started still shows the batch's), or -1.
pid_t childRunning(pid_t batch, const fs::path& scene) {
  std::ifstream in("/proc/" + std::to_string(batch) + "/task/" + std::to_string(batch) + "/children");
  for (pid_t pid; in >> pid;) {
    std::ifstream cmd("/proc/" + std::to_string(pid) + "/cmdline");
    std::vector<std::string> argv;
    for (std::string a; std::getline(cmd, a, '\0');) argv.push_back(a);
    if (argv.size() > 2 && argv[1] == "run" && argv[2] == scene.string()) return pid;
  }
  return -1;
}

std::vector<std::string> batchArgs(const std::vector<fs::path>& scenes, const fs::path& out,
                                   const std::vector<std::string>& more = {}) {
  std::vector<std::string> a = {"batch"};
  for (const fs::path& s : scenes) a.push_back(s.string());
  a.insert(a.end(), {"--out", out.string()});
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

// Two processes, one folder: a second batch (here --resume) into the folder
// of a batch still running is refused naming the holder, and the runs of a
// batch that is killed (SIGKILL: nothing of it can clean up) stop with it,
// checkpointing on the way out, instead of running on as orphans.
TEST(Batch, ASecondBatchIsRefusedAndTheRunsStopWhenTheBatchIsKilled) {
  const fs::path dir = tempDir("batch_lock"), out = dir / "out";
  const fs::path scene = writeScene(dir, "long", 1000000, 50);
  const pid_t batch = startMorphoflow(batchArgs({scene}, out, {"--quiet"}), dir / "batch.log");
  pid_t child = -1;
  ASSERT_TRUE(
      waitUntil([&] { return (child = childRunning(batch, scene)) > 0 && fs::exists(out / "long" / "frames"); }, 60));
  const CommandResult second = runMorphoflow("batch " + scene.string() + " --resume --quiet --out " + out.string());
  EXPECT_EQ(second.status, 2) << second.output;
  EXPECT_NE(second.output.find("in use by another morphoflow run (pid " + std::to_string(batch) + ")"),
            std::string::npos)
      << second.output;
  kill(batch, SIGKILL);
  EXPECT_EQ(waitMorphoflow(batch), 128 + SIGKILL);
  EXPECT_TRUE(waitUntil([&] { return kill(child, 0) != 0; }, 60)) << "the run outlived its batch";
  EXPECT_GT(countFiles(out / "long" / "checkpoints"), 0) << "the run stopped without its checkpoint";
  fs::remove_all(dir);
}

TEST(Batch, ACrashAndAKillNineInTwoScenesNeverStopTheOthers) {
  const fs::path dir = tempDir("batch_isolation"), out = dir / "out";
  const fs::path a = writeScene(dir, "a", 40, 10), b = writeScene(dir, "b", 30, 10);
  const fs::path segv = writeScene(dir, "segv", 1000000, 1000), oom = writeScene(dir, "oom", 1000000, 1000);
  const pid_t batch = startMorphoflow(batchArgs({segv, a, oom, b}, out, {"--jobs", "4"}), dir / "log.txt");
  pid_t p1 = -1, p2 = -1;
  ASSERT_TRUE(
      waitUntil([&] { return (p1 = childRunning(batch, segv)) > 0 && (p2 = childRunning(batch, oom)) > 0; }, 30));
  kill(p1, SIGSEGV);
  kill(p2, SIGKILL);  // what the out-of-memory killer sends
  EXPECT_EQ(waitMorphoflow(batch), 1);
  const std::string log = slurp(dir / "log.txt");
  const nlohmann::json s = readJson(out / "batch.json");
  EXPECT_EQ(s["exit_status"], 1);
  EXPECT_EQ(runNamed(s, "segv")["status"], "crashed");
  EXPECT_EQ(runNamed(s, "segv")["signal"], "SIGSEGV");
  EXPECT_EQ(runNamed(s, "oom")["status"], "killed");
  for (const auto& [name, steps, frames] : {std::tuple{"a", 40, 5}, std::tuple{"b", 30, 4}}) {
    const nlohmann::json& r = runNamed(s, name);
    EXPECT_EQ(r["status"], "completed") << name;
    EXPECT_EQ(r["exit_code"], 0);
    EXPECT_EQ(r["steps"], steps);
    // The summary agrees with the run's own folder.
    EXPECT_EQ(r["frames"], frames);
    EXPECT_EQ(countFiles(out / name / "frames"), frames);
    EXPECT_EQ(readJson(out / name / "run.json")["exit_state"], "completed");
    uintmax_t frameBytes = 0;
    for (const auto& e : fs::directory_iterator(out / name / "frames")) frameBytes += e.file_size();
    EXPECT_GE(r["bytes_written"].get<uintmax_t>(), frameBytes);
  }
  // The table on stdout: a line per scene with its status and folder.
  EXPECT_NE(log.find("crashed"), std::string::npos) << log;
  EXPECT_NE(log.find((out / "oom").string()), std::string::npos) << log;
  EXPECT_NE(log.find("2 of 4 runs completed"), std::string::npos) << log;
}

TEST(Batch, AnInvalidSceneStopsTheBatchBeforeAnythingRunsUnlessKeepGoing) {
  const fs::path dir = tempDir("batch_invalid");
  const fs::path good = writeScene(dir, "good", 20, 10), bad = writeScene(dir, "bad", 20, 10, "colour = \"red\"\n");
  CommandResult r = runMorphoflow("batch " + good.string() + " " + bad.string() + " --out " + (dir / "o1").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(bad.string() + ":25:"), std::string::npos) << r.output;  // file:line:column
  EXPECT_NE(r.output.find("--keep-going"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "o1" / "good"));

  r = runMorphoflow("batch " + good.string() + " " + bad.string() + " --keep-going --quiet --out " +
                    (dir / "o2").string());
  EXPECT_EQ(r.status, 2) << r.output;
  const nlohmann::json s = readJson(dir / "o2" / "batch.json");
  EXPECT_EQ(runNamed(s, "good")["status"], "completed");
  EXPECT_EQ(runNamed(s, "bad")["status"], "invalid");
  EXPECT_NE(runNamed(s, "bad")["error"].get<std::string>().find("colour"), std::string::npos);
  EXPECT_EQ(countFiles(dir / "o2" / "good" / "frames"), 3);
}

TEST(Batch, SetAppliesToEveryRunAndJobsDivideTheThreads) {
  const fs::path dir = tempDir("batch_set");
  const fs::path a = writeScene(dir, "a", 50, 10), b = writeScene(dir, "b", 60, 10);
  CommandResult one =
      runMorphoflow("run " + a.string() + " --quiet --set time.steps=1 --out " + (dir / "one").string());
  ASSERT_EQ(one.status, 0) << one.output;
  const int machine = readJson(dir / "one" / "run.json")["threads"];
  // Scene files may follow a --set (each takes one value).
  CommandResult r = runMorphoflow("batch --set time.steps=7 " + a.string() + " --set output.every=7 " + b.string() +
                                  " --jobs 2 --quiet --out " + (dir / "o").string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* name : {"a", "b"}) {
    const nlohmann::json j = readJson(dir / "o" / name / "run.json");
    EXPECT_EQ(j["steps"], 7) << name;
    EXPECT_EQ(j["scene"]["time"]["steps"], 7);
    EXPECT_EQ(j["threads"], std::max(1, machine / 2));
    EXPECT_EQ(countFiles(dir / "o" / name / "frames"), 2);
  }
}

// --resume with a changed --set (docs/batch.md): a run completed with other
// settings runs again, afresh, to the new settings; with the same ones it is skipped.
TEST(Batch, ResumeWithAChangedSetRunsTheSceneAgain) {
  const fs::path dir = tempDir("batch_resume_set"), out = dir / "out";
  const fs::path scene = writeScene(dir, "gs", 40, 10);
  const std::string base = "batch " + scene.string() + " --quiet --out " + out.string();
  ASSERT_EQ(runMorphoflow(base + " --set time.steps=20").status, 0);
  CommandResult r = runMorphoflow(base + " --set time.steps=40 --resume");
  EXPECT_EQ(r.status, 0) << r.output;
  const nlohmann::json run = readJson(out / "gs" / "run.json");
  EXPECT_EQ(run["exit_state"], "completed");
  EXPECT_EQ(run["steps"], 40);
  EXPECT_EQ(runNamed(readJson(out / "batch.json"), "gs")["status"], "completed");
  r = runMorphoflow(base + " --set time.steps=40 --resume");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(runNamed(readJson(out / "batch.json"), "gs")["status"], "skipped");
  fs::remove_all(dir);
}

// --resume notices a changed input file (a map's image rewritten): the run
// is done again, not skipped as completed; unchanged, it is skipped.
TEST(Batch, ResumeRunsASceneAgainWhenAnInputFileChanged) {
  const fs::path dir = tempDir("batch_resume_input"), out = dir / "out";
  auto image = [&](int grey) {
    std::ofstream(dir / "m.pgm", std::ios::binary) << "P5 8 8 255\n" << std::string(64 + grey % 2, char(grey));
  };
  image(100);
  const fs::path scene =
      writeScene(dir, "mapped", 20, 10, "[rd.maps]\nF = { image = \"m.pgm\", range = [0.03, 0.05] }\n");
  const std::string cmd = "batch " + scene.string() + " --quiet --out " + out.string();
  ASSERT_EQ(runMorphoflow(cmd).status, 0);
  ASSERT_EQ(runMorphoflow(cmd + " --resume").status, 0);
  EXPECT_EQ(runNamed(readJson(out / "batch.json"), "mapped")["status"], "skipped");
  image(201);  // other pixels, another size
  ASSERT_EQ(runMorphoflow(cmd + " --resume").status, 0);
  EXPECT_EQ(runNamed(readJson(out / "batch.json"), "mapped")["status"], "completed");
  fs::remove_all(dir);
}

TEST(Batch, SigintCheckpointsTheRunningScenesAndResumeFinishesOnlyWhatIsLeft) {
  const fs::path dir = tempDir("batch_resume"), out = dir / "out";
  const fs::path quick = writeScene(dir, "quick", 20, 10),
                 slow = writeScene(dir, "slow", 30000, 1000, "checkpoint_every = 1\n");
  const pid_t batch = startMorphoflow(batchArgs({quick, slow}, out, {"--jobs", "2"}), dir / "log1.txt");
  // The batch has seen the quick scene's process end (its summary says so;
  // run.json alone is written just before the process exits, and a signal
  // forwarded in between would stop it) and the slow one has checkpointed.
  auto quickDone = [&] {
    std::error_code ec;
    if (!fs::exists(out / "batch.json", ec)) return false;
    try {
      return runNamed(readJson(out / "batch.json"), "quick").value("status", "") == "completed";
    } catch (const std::exception&) {
      return false;
    }
  };
  ASSERT_TRUE(waitUntil(
      [&] {
        return fs::exists(out / "slow" / "checkpoints") && countFiles(out / "slow" / "checkpoints") > 0 && quickDone();
      },
      60));
  kill(batch, SIGINT);
  EXPECT_EQ(waitMorphoflow(batch), 130);
  nlohmann::json s = readJson(out / "batch.json");
  EXPECT_EQ(runNamed(s, "quick")["status"], "completed");
  EXPECT_EQ(runNamed(s, "slow")["status"], "interrupted");
  EXPECT_EQ(readJson(out / "slow" / "run.json")["exit_state"], "interrupted");
  EXPECT_NE(slurp(dir / "log1.txt").find("interrupted"), std::string::npos);
  const long stoppedAt = readJson(out / "slow" / "run.json")["steps"];
  const auto quickWritten = fs::last_write_time(out / "quick" / "run.json");

  // The completed scene is skipped (its run.json untouched); the interrupted one continues.
  CommandResult r =
      runMorphoflow("batch " + quick.string() + " " + slow.string() + " --resume --quiet --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.output;
  s = readJson(out / "batch.json");
  EXPECT_EQ(runNamed(s, "quick")["status"], "skipped");
  EXPECT_EQ(fs::last_write_time(out / "quick" / "run.json"), quickWritten);
  EXPECT_EQ(runNamed(s, "slow")["status"], "completed") << runNamed(s, "slow");
  EXPECT_TRUE(runNamed(s, "slow")["resumed"].get<bool>());
  const nlohmann::json j = readJson(out / "slow" / "run.json");
  EXPECT_EQ(j["steps"], 30000);
  EXPECT_GT(stoppedAt, 0);
  EXPECT_TRUE(j.contains("resumed_from"));
}

TEST(Batch, NamesAndFoldersAreUniqueAndAFolderHoldsOneBatch) {
  const fs::path dir = tempDir("batch_names");
  fs::create_directories(dir / "x");
  const fs::path a = writeScene(dir, "same", 10, 10), b = writeScene(dir / "x", "same", 10, 10);
  CommandResult r = runMorphoflow("batch " + a.string() + " " + a.string() + " --out " + (dir / "o").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("listed twice"), std::string::npos) << r.output;

  r = runMorphoflow("batch " + a.string() + " " + b.string() + " --quiet --out " + (dir / "o").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(readJson(dir / "o" / "same" / "run.json")["scene_file"], a.string());
  EXPECT_EQ(readJson(dir / "o" / "same-2" / "run.json")["scene_file"], b.string());

  const fs::path c = writeScene(dir, "other", 10, 10);
  r = runMorphoflow("batch " + c.string() + " --out " + (dir / "o").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("another batch"), std::string::npos) << r.output;
}

TEST(Batch, BadOptionsAreUserErrors) {
  const fs::path dir = tempDir("batch_options");
  const std::string a = writeScene(dir, "a", 10, 10).string(), out = " --out " + (dir / "o").string();
  for (const std::string& args : {"batch " + a + " --shard 1/2x" + out, "batch " + a + " --shard 2/2" + out,
                                  "batch " + a + " --shard 1" + out, "batch " + a + " --jobs 0" + out, "batch" + out,
                                  "sweep " + a + " --vary rd.parameters.F=0.01:0.02" + out,
                                  "sweep " + a + " --vary rd.parameters.F=0.01:0.02:3x" + out,
                                  "sweep " + a + " --vary 'rd.parameters.F=[0.01,' " + out,
                                  "sweep " + a + " --vary rd.parameters.F=[] " + out,
                                  "sweep " + a + " --vary rd.parameters.F=[0.1] --set rd.parameters.F=0.2" + out,
                                  "run " + a + " --frames 1x:2y" + out, "gather " + (dir / "nothing").string()}) {
    CommandResult r = runMorphoflow(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_FALSE(r.output.empty()) << args;  // what was wrong
  }
}

// gather trusts nothing it reads: a shard summary with a key of the wrong
// type or missing, a last frame outside the batch folder (it would be read
// into the contact sheet) or not a file, a run list shorter than the plan,
// a huge N in a file name, a FIFO named as a summary: each is exit 2 naming
// the file (never a crash, a hang or a silent summary), and the intact
// shards gather again.
TEST(Batch, GatherRefusesSummariesThatDoNotHold) {
  const fs::path dir = tempDir("batch_gather_hostile"), out = dir / "out";
  std::string list;
  for (const char* n : {"g0", "g1", "g2"}) list += writeScene(dir, n, 10, 10).string() + " ";
  for (const char* shard : {"0/2", "1/2"})
    ASSERT_EQ(runMorphoflow("batch " + list + "--shard " + shard + " --quiet --out " + out.string()).status, 0);
  const fs::path file = out / "batch.shard-0-of-2.json";
  ASSERT_TRUE(fs::exists(file));
  const nlohmann::json good = readJson(file);
  ASSERT_EQ(runMorphoflow("gather " + out.string()).status, 0);
  const std::vector<std::pair<std::string, std::function<void(nlohmann::json*)>>> bad = {
      {"steps a string", [](nlohmann::json* j) { (*j)["runs"][0]["steps"] = "x"; }},
      {"no last_frame", [](nlohmann::json* j) { (*j)["runs"][0].erase("last_frame"); }},
      {"negative bytes", [](nlohmann::json* j) { (*j)["runs"][0]["bytes_written"] = -5; }},
      {"last frame outside", [](nlohmann::json* j) { (*j)["runs"][0]["last_frame"] = "/etc/passwd"; }},
      {"last frame up", [](nlohmann::json* j) { (*j)["runs"][0]["last_frame"] = "../../x.png"; }},
      {"last frame missing", [](nlohmann::json* j) { (*j)["runs"][0]["last_frame"] = "g0/frames/999999.png"; }},
      {"a run short", [](nlohmann::json* j) { (*j)["runs"].erase(1); }},
      {"runs not a list", [](nlohmann::json* j) { (*j)["runs"] = 3; }},
  };
  for (const auto& [what, change] : bad) {
    nlohmann::json j = good;
    change(&j);
    std::ofstream(file, std::ios::trunc) << j.dump();
    const CommandResult r = runMorphoflow("gather " + out.string());
    EXPECT_EQ(r.status, 2) << what << "\n" << r.output;
    EXPECT_NE(r.output.find(what == "a run short" ? out.string() : file.string()), std::string::npos) << what << "\n"
                                                                                                      << r.output;
  }
  std::ofstream(file, std::ios::trunc) << good.dump();
  const fs::path huge = out / "batch.shard-1-of-99999999999999999999.json", fifo = out / "batch.shard-3-of-4.json";
  std::ofstream(huge) << good.dump();
  CommandResult r = runMorphoflow("gather " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  fs::remove(huge);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  r = runMorphoflow("gather " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(fifo.string()), std::string::npos) << r.output;
  fs::remove(fifo);
  EXPECT_EQ(runMorphoflow("gather " + out.string()).status, 0);
  fs::remove_all(dir);
}

TEST(Batch, ShardsSplitTheScenesAndGatherMergesTheirSummaries) {
  const fs::path dir = tempDir("batch_shards"), out = dir / "out";
  std::vector<fs::path> scenes;
  for (const char* n : {"s0", "s1", "s2"}) scenes.push_back(writeScene(dir, n, 10, 10));
  std::string list;
  for (const fs::path& s : scenes) list += s.string() + " ";
  CommandResult r = runMorphoflow("batch " + list + "--shard 0/2 --quiet --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "s0") && fs::exists(out / "s2") && !fs::exists(out / "s1"));
  r = runMorphoflow("gather " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;  // shard 1 has not run
  EXPECT_NE(r.output.find("shards 1 of 2"), std::string::npos) << r.output;
  r = runMorphoflow("batch " + list + "--shard 1/2 --quiet --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  r = runMorphoflow("gather " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json s = readJson(out / "batch.json");
  ASSERT_EQ(s["runs"].size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(s["runs"][i]["folder"], "s" + std::to_string(i));
    EXPECT_EQ(s["runs"][i]["status"], "completed");
  }
}

// Pearson's classes: the last frame of each (F, k) in a grid, columns by F,
// rows by k; each cell of the sheet shows its variant's last frame.
TEST(Sweep, EveryCombinationInItsFolderWithACsvAndAContactSheet) {
  const fs::path dir = tempDir("sweep"), out = dir / "out";
  const fs::path scene = writeScene(dir, "gs", 200, 100);
  CommandResult r = runMorphoflow(
      "sweep " + scene.string() +
      " --vary rd.parameters.F=0.02:0.04:2 --vary 'rd.parameters.k=[0.055,0.065]' --jobs 2 --quiet --out " +
      out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::vector<std::string> folders;
  for (const char* F : {"0.02", "0.04"})
    for (const char* k : {"0.055", "0.065"}) {
      const std::string f = std::string("rd.parameters.F=") + F + ",rd.parameters.k=" + k;
      folders.push_back(f);
      const nlohmann::json j = readJson(out / f / "run.json");
      EXPECT_DOUBLE_EQ(j["scene"]["rd"]["parameters"]["F"].get<double>(), std::stod(F)) << f;
      EXPECT_DOUBLE_EQ(j["scene"]["rd"]["parameters"]["k"].get<double>(), std::stod(k)) << f;
    }
  std::ifstream csv(out / "sweep.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "rd.parameters.F,rd.parameters.k,status,exit_code,wall_seconds,last_frame");
  std::vector<morphoflow::GrayImage> frames;
  for (size_t i = 0; std::getline(csv, line); ++i) {
    ASSERT_LT(i, folders.size());
    EXPECT_NE(line.find(",completed,0,"), std::string::npos) << line;
    const std::string last = out / folders[i] / "frames" / "000002.png";
    EXPECT_NE(line.find(folders[i] + "/frames/000002.png"), std::string::npos) << line;
    morphoflow::GrayImage g;
    std::string error;
    ASSERT_TRUE(morphoflow::readGrayImage(last, &g, &error)) << error;
    frames.push_back(g);
  }
  ASSERT_EQ(frames.size(), 4u);

  // Cells are the non-white runs (wider than any label) across the sheet's rows.
  morphoflow::GrayImage sheet;
  std::string error;
  ASSERT_TRUE(morphoflow::readGrayImage((out / "contact_sheet.png").string(), &sheet, &error)) << error;
  auto white = [&](int x, int y) { return sheet.pixels[size_t(y) * size_t(sheet.width) + size_t(x)] > 0.999f; };
  std::vector<std::pair<int, int>> cols, rows;
  auto runs = [](int n, auto isWhite, std::vector<std::pair<int, int>>* out) {
    for (int i = 0; i < n;) {
      int j = i;
      while (j < n && !isWhite(j)) ++j;
      if (j - i > 40) out->emplace_back(i, j);
      i = j + 1;
    }
  };
  // A scan line through a cell's middle finds the column boundaries, and one down a column the rows.
  for (int y = 0; y < sheet.height && cols.size() < 2; ++y) {
    cols.clear();
    runs(sheet.width, [&](int x) { return white(x, y); }, &cols);
  }
  ASSERT_EQ(cols.size(), 2u);
  const int xMid = (cols[0].first + cols[0].second) / 2;
  runs(sheet.height, [&](int y) { return white(xMid, y); }, &rows);
  ASSERT_EQ(rows.size(), 2u);
  for (int c = 0; c < 2; ++c)
    for (int row = 0; row < 2; ++row) {
      double sum = 0;
      int n = 0;
      for (int y = rows[size_t(row)].first; y < rows[size_t(row)].second; ++y)
        for (int x = cols[size_t(c)].first; x < cols[size_t(c)].second; ++x, ++n)
          sum += sheet.pixels[size_t(y) * size_t(sheet.width) + size_t(x)];
      const morphoflow::GrayImage& f = frames[size_t(c) * 2 + size_t(row)];  // F slowest: column c, row k
      double fsum = 0;
      for (float v : f.pixels) fsum += v;
      EXPECT_NEAR(sum / n, fsum / double(f.pixels.size()), 0.02) << "column " << c << " row " << row;
    }
}
