// Outputs that cannot be turned against the user or lost: a scene's name
// never places a file outside --out; an --out that is a file or under
// /proc, /sys or /dev, and a write that fails, are exit 2 naming the path;
// a failed write leaves nothing empty or cut short under a final name; a
// device node or pipe at an output path is never replaced; a new run never
// mixes its frames with an earlier run's; SIGTERM also stops ffmpeg and
// leaves no .part file.
#include <gtest/gtest.h>

#include <sys/mount.h>
#include <sys/stat.h>

#include <csignal>
#include <fstream>

#include <nlohmann/json.hpp>

#include "render/image_io.h"
#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

const std::string kScene = sceneFile("coupled/cavity_gray_scott.toml");
const std::string kSmall =
    " --set grid.resolution=[24,24] --set rd.resolution=[24,24] --set time.steps=40 --set output.every=4"
    " --set output.video=false --quiet";

// Every file under `dir` (recursively).
std::vector<fs::path> filesUnder(const fs::path& dir) {
  std::vector<fs::path> v;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (!e.is_directory()) v.push_back(e.path());
  return v;
}

// No file under `out` is empty, cut short or left under a temporary name:
// every image decodes, every JSON parses.
void expectOnlyCompleteFiles(const fs::path& out) {
  for (const fs::path& p : filesUnder(out)) {
    const std::string name = p.filename().string();
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << p;
    EXPECT_EQ(name.find(".part"), std::string::npos) << p;
    EXPECT_GT(fs::file_size(p), 0u) << p;
    if (p.extension() == ".png" || p.extension() == ".exr") {
      morphoflow::GrayImage img;
      std::string err;
      EXPECT_TRUE(morphoflow::readGrayImage(p.string(), &img, &err)) << p << ": " << err;
    }
    if (p.extension() == ".json") {
      EXPECT_NO_THROW(nlohmann::json::parse(std::ifstream(p))) << p;
    }
  }
}

}  // namespace

TEST(OutputSafety, ASceneNameNeverPlacesAFileOutsideOut) {
  const fs::path dir = tempDir("safety_name");
  const fs::path out = dir / "a" / "out";
  for (const char* name : {"../../escaped", "/tmp/absolute_escape", "..", "sub/dir/name"}) {
    fs::remove_all(dir);
    fs::create_directories(out);
    CommandResult r = runMorphoflow("run " + kScene + kSmall + " --set 'name=\"" + name +
                                    "\"' --set output.vdb=true --set output.video=true --out " + out.string());
    EXPECT_EQ(r.status, 0) << r.output;
    for (const fs::path& p : filesUnder(dir)) {
      const std::string rel = fs::relative(p, out).string();
      EXPECT_NE(rel.substr(0, 2), "..") << name << " wrote " << p;
    }
    EXPECT_FALSE(fs::exists("/tmp/absolute_escape.mp4"));
    const std::vector<fs::path> vdb = filesUnder(out / "vdb");
    ASSERT_FALSE(vdb.empty());
    for (const fs::path& p : vdb) EXPECT_EQ(p.parent_path(), out / "vdb") << p;
  }
  fs::remove_all(dir);
}

TEST(OutputSafety, AnOutThatCannotHoldARunIsExitTwoNamingIt) {
  const fs::path dir = tempDir("safety_out");
  std::ofstream(dir / "a_file") << "not a folder";
  for (const std::string& out : {(dir / "a_file").string(), (dir / "a_file" / "below").string(),
                                 std::string("/proc/morphoflow_out"), std::string("/sys/morphoflow_out"),
                                 std::string("/dev/null"), std::string("/dev/morphoflow_out")}) {
    CommandResult r = runMorphoflow("run " + kScene + kSmall + " --out " + out);
    EXPECT_EQ(r.status, 2) << out << ": " << r.output;
    EXPECT_NE(r.output.find(out), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  }
  EXPECT_EQ(fs::file_size(dir / "a_file"), 12u);  // untouched
  // An empty --out names no folder: exit 2 saying so, for run and batch.
  for (const std::string& command :
       {"run " + kScene + kSmall + " --out ''", "batch " + kScene + kSmall + " --out ''"}) {
    CommandResult r = runMorphoflow(command);
    EXPECT_EQ(r.status, 2) << command << ": " << r.output;
    EXPECT_NE(r.output.find("--out"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  }
  fs::remove_all(dir);
}

TEST(OutputSafety, AFailedWriteIsExitTwoAndLeavesNothingCutShort) {
  const fs::path dir = tempDir("safety_fsize");
  // A file-size limit (SIGXFSZ ignored: writes past it fail with EFBIG) stands
  // in for a full disk: the same failed write(2).
  const std::string run = std::string(MORPHOFLOW_BINARY) + " run " + kScene + kSmall +
                          " --set output.fields=true --set output.vdb=true --out " + (dir / "out").string();
  CommandResult r;
  {
    const std::string cmd = "sh -c \"trap '' XFSZ; ulimit -f 8; exec " + run + "\" 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    const int st = pclose(p);
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  }
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find((dir / "out").string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("larger than this process may write"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  expectOnlyCompleteFiles(dir / "out");
  fs::remove_all(dir);
}

TEST(OutputSafety, AFullDiskIsExitTwoAndLeavesNothingCutShort) {
  const fs::path dir = tempDir("safety_full");
  const fs::path disk = dir / "disk";
  fs::create_directories(disk);
  if (::mount("tmpfs", disk.c_str(), "tmpfs", 0, "size=160k") != 0)
    GTEST_SKIP() << "cannot mount a small tmpfs here (needs root): " << std::strerror(errno);
  CommandResult r = runMorphoflow("run " + kScene + kSmall + " --set output.fields=true --set time.steps=400 --out " +
                                  (disk / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("the disk is full"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find((disk / "out").string()), std::string::npos) << r.output;
  expectOnlyCompleteFiles(disk / "out");
  ::umount(disk.c_str());
  fs::remove_all(dir);
}

TEST(OutputSafety, ANonRegularFileAtAnOutputPathIsNeverReplaced) {
  const fs::path dir = tempDir("safety_fifo");
  for (const char* rel : {"frames/000003.png", "frames/000003.png.tmp", "run.json", "log.txt"}) {
    fs::remove_all(dir / "out");
    fs::create_directories(dir / "out" / "frames");
    const fs::path fifo = dir / "out" / rel;
    ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
    CommandResult r = runMorphoflow("run " + kScene + kSmall + " --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << rel << ": " << r.output;
    EXPECT_NE(r.output.find(fifo.string()), std::string::npos) << r.output;
    struct stat st;
    ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
    EXPECT_TRUE(S_ISFIFO(st.st_mode)) << rel << " was replaced";
  }
  fs::remove_all(dir);
}

TEST(OutputSafety, ANewRunRemovesTheEarlierRunsOutputsOnly) {
  const fs::path dir = tempDir("safety_rerun");
  const fs::path out = dir / "out";
  ASSERT_EQ(
      runMorphoflow("run " + kScene + kSmall + " --set output.every=2 --set output.fields=true --out " + out.string())
          .status,
      0);
  std::ofstream(out / "notes.txt") << "mine";
  std::ofstream(out / "frames" / "reference.png") << "mine too";
  ASSERT_EQ(runMorphoflow("run " + kScene + kSmall + " --set output.every=8 --out " + out.string()).status, 0);
  int frames = 0;
  for (const fs::path& p : filesUnder(out / "frames")) frames += p.filename() != "reference.png";
  EXPECT_EQ(frames, 6);  // steps 0, 8, ..., 40: the second run's only
  EXPECT_FALSE(fs::exists(out / "fields"));
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_TRUE(fs::exists(out / "frames" / "reference.png"));
  fs::remove_all(dir);
}

// Every kind of output a run writes into its folders (run/output_kinds.h):
// a run with frames, field dumps, normal and height maps, VDB volumes and
// checkpoints, then one that writes frames (and its final checkpoint) only:
// the folders of the kinds it no longer writes are gone, and the frames are its own.
TEST(OutputSafety, EveryKindOfEarlierOutputIsRemoved) {
  const fs::path dir = tempDir("safety_every_kind");
  const fs::path out = dir / "out";
  ASSERT_EQ(runMorphoflow("run " + kScene + kSmall +
                          " --set output.every=4 --set output.fields=true --set output.normal_map=true"
                          " --set output.vdb=true --set output.checkpoint_every=1 --out " + out.string())
                .status,
            0);
  for (const char* folder : {"frames", "fields", "normals", "height", "vdb", "checkpoints"})
    ASSERT_FALSE(filesUnder(out / folder).empty()) << folder << " not written by the first run";
  ASSERT_EQ(runMorphoflow("run " + kScene + kSmall + " --set output.every=8 --set output.checkpoint_every=0 --out " +
                          out.string())
                .status,
            0);
  for (const char* folder : {"fields", "normals", "height", "vdb"})
    EXPECT_FALSE(fs::exists(out / folder)) << folder << " left from the first run";
  EXPECT_EQ(filesUnder(out / "frames").size(), 6u);  // steps 0, 8, ..., 40: the second run's only
  fs::remove_all(dir);
}

// Two processes, one output folder: while a run writes its folder, a second
// run into it is refused (exit 2 naming the holder's pid) and deletes
// nothing of the first run's; once the first has ended, the folder is free.
TEST(OutputSafety, AFolderInUseIsRefusedToASecondRun) {
  const fs::path dir = tempDir("safety_lock");
  const fs::path out = dir / "out";
  const pid_t first =
      startMorphoflow({"run", kScene, "--set", "grid.resolution=[24,24]", "--set", "rd.resolution=[24,24]", "--set",
                       "time.steps=1000000", "--set", "output.every=20", "--set", "output.video=false", "--quiet",
                       "--out", out.string()},
                      dir / "log");
  ASSERT_TRUE(waitUntil([&] { return fs::exists(out / "frames" / "000001.png"); }, 60));
  const CommandResult second = runMorphoflow("run " + kScene + kSmall + " --out " + out.string());
  EXPECT_EQ(second.status, 2) << second.output;
  EXPECT_NE(second.output.find("in use by another morphoflow run (pid " + std::to_string(first) + ")"),
            std::string::npos)
      << second.output;
  EXPECT_TRUE(fs::exists(out / "frames" / "000000.png")) << "the second run deleted the first run's frames";
  kill(first, SIGINT);
  EXPECT_EQ(waitMorphoflow(first), 130);
  EXPECT_EQ(runMorphoflow("run " + kScene + kSmall + " --out " + out.string()).status, 0);
  fs::remove_all(dir);
}

TEST(OutputSafety, SigtermStopsFfmpegAndLeavesNoPartFile) {
  const fs::path dir = tempDir("safety_ffmpeg");
  const fs::path bin = dir / "bin";
  fs::create_directories(bin);
  // An ffmpeg that starts its output and hangs.
  {
    std::ofstream f(bin / "ffmpeg");
    f << "#!/bin/sh\nfor last; do :; done\necho started > \"$last\"\necho $$ > " << (dir / "ffmpeg.pid").string()
      << "\nexec sleep 60\n";
  }
  fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
  const std::string path = bin.string() + ":" + std::getenv("PATH");
  setenv("PATH", path.c_str(), 1);
  const fs::path out = dir / "out";
  const pid_t pid = startMorphoflow(
      {"run", kScene, "--set", "grid.resolution=[24,24]", "--set", "rd.resolution=[24,24]", "--set", "time.steps=8",
       "--set", "output.every=4", "--set", "output.video=true", "--quiet", "--out", out.string()},
      dir / "log");
  ASSERT_TRUE(waitUntil([&] { return fs::exists(dir / "ffmpeg.pid") && fs::file_size(dir / "ffmpeg.pid") > 0; }, 60));
  const pid_t ffmpeg =
      std::stoi(std::string(std::istreambuf_iterator<char>(std::ifstream(dir / "ffmpeg.pid").rdbuf()), {}));
  if (pid > 0) kill(pid, SIGTERM);
  EXPECT_EQ(waitMorphoflow(pid), 143);
  EXPECT_TRUE(waitUntil([&] { return kill(ffmpeg, 0) != 0; }, 10)) << "ffmpeg still runs";
  for (const fs::path& p : filesUnder(out)) EXPECT_EQ(p.string().find(".part"), std::string::npos) << p;
  EXPECT_FALSE(fs::exists(out / "cavity_gray_scott.mp4"));
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(out / "run.json"))["exit_state"], "interrupted");
  fs::remove_all(dir);
}
