// Checkpoints and --resume: a run killed midway (SIGKILL: no chance to clean
// up) and resumed writes every file bit for bit as an uninterrupted run does,
// in 2D and 3D, coupled, reaction-diffusion-only and fluid-only; SIGINT and
// SIGTERM checkpoint and exit 130 / 143; a changed scene, a missing or a
// damaged checkpoint are clear errors or fall back to an intact one. VDB
// volumes are compared too: their UUID comes from their content.
#include <gtest/gtest.h>

#include <csignal>
#include <cstring>
#include <functional>
#include <fstream>

#include <nlohmann/json.hpp>
#include <xxhash.h>

#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

struct ResumeCase {
  std::string name, scene;
  std::vector<std::string> sets;
};
void PrintTo(const ResumeCase& c, std::ostream* os) { *os << c.name; }

std::vector<std::string> runArgs(const ResumeCase& c, const fs::path& out) {
  std::vector<std::string> a = {"run", sceneFile(c.scene), "--quiet", "--out", out.string()};
  for (const std::string& s : c.sets) a.insert(a.end(), {"--set", s});
  return a;
}

std::string join(const std::vector<std::string>& args) {
  std::string s;
  for (const std::string& a : args) s += " '" + a + "'";
  return s;
}

std::vector<fs::path> checkpoints(const fs::path& out) {
  std::vector<fs::path> v;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out / "checkpoints", ec))
    if (e.path().extension() == ".ckpt") v.push_back(e.path());
  std::sort(v.begin(), v.end());
  return v;
}

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Every frame, dump and probe file of `a` is in `b`, byte for byte; their count.
int expectSameFiles(const fs::path& a, const fs::path& b) {
  int n = 0;
  for (const char* sub : {"frames", "fields", "profiles", "vdb"}) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(a / sub, ec)) {
      const fs::path rel = fs::path(sub) / e.path().filename();
      EXPECT_TRUE(fs::exists(b / rel)) << rel;
      EXPECT_TRUE(bytes(a / rel) == bytes(b / rel)) << rel << " differs";
      ++n;
    }
  }
  if (fs::exists(a / "forces.csv")) {
    EXPECT_EQ(bytes(a / "forces.csv"), bytes(b / "forces.csv"));
    ++n;
  }
  return n;
}

// Starts the run into `out` and kills it with `sig` once it has written its
// first checkpoint; the exit status.
int interruptAfterFirstCheckpoint(const ResumeCase& c, const fs::path& out, int sig) {
  fs::create_directories(out.parent_path());
  const pid_t pid = startMorphoflow(runArgs(c, out), out.string() + ".log");
  EXPECT_GT(pid, 0);
  EXPECT_TRUE(waitUntil([&] { return !checkpoints(out).empty(); }, 120)) << "no checkpoint appeared";
  if (pid > 0) kill(pid, sig);
  return waitMorphoflow(pid);
}

class KillAndResume : public ::testing::TestWithParam<ResumeCase> {};

TEST_P(KillAndResume, WritesWhatAnUninterruptedRunWrites) {
  const ResumeCase& c = GetParam();
  const fs::path dir = tempDir("resume_" + c.name);
  CommandResult whole = runMorphoflow(join(runArgs(c, dir / "whole")));
  ASSERT_EQ(whole.status, 0) << whole.output;

  const int killed = interruptAfterFirstCheckpoint(c, dir / "cut", SIGKILL);
  ASSERT_EQ(killed, 128 + SIGKILL) << "the run ended before it could be killed; make it longer";
  const nlohmann::json before = nlohmann::json::parse(std::ifstream(dir / "whole" / "run.json"));
  std::vector<std::string> resume = runArgs(c, dir / "cut");
  resume.push_back("--resume");
  CommandResult r = runMorphoflow(join(resume));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GT(expectSameFiles(dir / "whole", dir / "cut"), 4);
  const nlohmann::json after = nlohmann::json::parse(std::ifstream(dir / "cut" / "run.json"));
  EXPECT_EQ(after["exit_state"], "completed");
  EXPECT_TRUE(after.contains("resumed_from"));
  EXPECT_EQ(after["steps"], before["steps"]);
  EXPECT_EQ(after["frames_written"], before["frames_written"]);
  EXPECT_EQ(after["settings_hash"], before["settings_hash"]);
  fs::remove_all(dir);
}

const std::vector<std::string> kCheckpointOften = {"output.fields=true", "output.checkpoint_every=1"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, KillAndResume,
    ::testing::Values(
        ResumeCase{"coupled_2d", "coupled/cavity_gray_scott.toml",
                   with({"grid.resolution=[48,48]", "rd.resolution=[64,64]", "time.steps=4000", "output.every=100",
                         "output.video=false"},
                        kCheckpointOften)},
        ResumeCase{"coupled_3d", "coupled/cavity_gray_scott_3d.toml",
                   with({"grid.resolution=[16,16,16]", "rd.resolution=[16,16,16]", "time.steps=1500", "output.every=50",
                         "output.video=false", "output.vdb=true", "output.nanovdb=true"},
                        kCheckpointOften)},
        ResumeCase{"rd_only_2d", "rd/seeds/kim_lin_lobes3.toml",
                   with({"grid.resolution=[64,64]", "time.steps=3000", "output.every=100"}, kCheckpointOften)},
        ResumeCase{"rd_only_3d", "rd/turing_lawlor.toml",
                   with({"grid.resolution=[24,24,24]", "domain.size=[24,24,24]", "time.steps=1500", "output.every=50"},
                        kCheckpointOften)},
        ResumeCase{"rd_fused_explicit", "rd/turing_lawlor.toml",
                   with({"grid.resolution=[128,128]", "domain.size=[128,128]", "rd.integrator=\"explicit\"",
                         "time.dt=0.5", "time.steps=100000", "output.every=5000"},
                        kCheckpointOften)},
        ResumeCase{"fluid_probes", "flow_past_obstacle.toml",
                   with({"grid.resolution=[220,41]", "time.duration=4", "output.every=40"}, kCheckpointOften)},
        // a moving obstacle: the constraints rebuilt where the checkpoint's time puts it
        ResumeCase{"moving_obstacle", "vfx/paddle_gray_scott.toml",
                   with({"grid.resolution=[48,48]", "rd.resolution=[64,64]", "time.steps=3000", "output.every=100",
                         "output.video=false"},
                        kCheckpointOften)},
        ResumeCase{"towed_cylinder", "flow/towed_cylinder.toml",
                   with({"grid.resolution=[160,40]", "time.duration=6", "output.every=40", "output.video=false"},
                        kCheckpointOften)},
        // stops at steady state (time.until_steady): at the same step
        ResumeCase{"fluid_until_steady", "lid_driven_cavity.toml",
                   with({"grid.resolution=[96,96]", "time.until_steady=1e-5", "output.every=50", "output.images=false"},
                        kCheckpointOften)}),
    [](const ::testing::TestParamInfo<ResumeCase>& i) { return i.param.name; });

const ResumeCase kCoupled{"coupled", "coupled/cavity_gray_scott.toml",
                          {"grid.resolution=[48,48]", "rd.resolution=[64,64]", "time.steps=6000", "output.every=100",
                           "output.video=false", "output.checkpoint_every=1"}};

}  // namespace

TEST(Resume, SigintAndSigtermCheckpointAndExit130And143) {
  const fs::path dir = tempDir("resume_signals");
  for (auto [sig, status, name] : {std::tuple{SIGINT, 130, "SIGINT"}, std::tuple{SIGTERM, 143, "SIGTERM"}}) {
    const fs::path out = dir / name;
    EXPECT_EQ(interruptAfterFirstCheckpoint(kCoupled, out, sig), status);
    const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "run.json"));
    EXPECT_EQ(j["exit_state"], "interrupted");
    const std::string log = bytes(out / "log.txt");
    EXPECT_NE(log.find(std::string("interrupted by ") + name), std::string::npos) << log;
    // The checkpoint it names is the newest, at the step where it stopped.
    const std::vector<fs::path> c = checkpoints(out);
    ASSERT_FALSE(c.empty());
    EXPECT_NE(log.find(c.back().string()), std::string::npos) << log;
    EXPECT_EQ(std::stol(c.back().stem().string()), j["steps"].get<long>());
  }
  fs::remove_all(dir);
}

TEST(Resume, RefusesAChangedSceneUnlessForced) {
  const fs::path dir = tempDir("resume_changed");
  ASSERT_EQ(interruptAfterFirstCheckpoint(kCoupled, dir / "out", SIGTERM), 143);
  std::vector<std::string> a = runArgs(kCoupled, dir / "out");
  a.insert(a.end(), {"--set", "rd.parameters.F=0.031", "--resume"});
  CommandResult r = runMorphoflow(join(a));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("rd.parameters.F"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  a.push_back("--force");
  r = runMorphoflow(join(a));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "out" / "run.json"))["exit_state"], "completed");
  fs::remove_all(dir);
}

TEST(Resume, WithoutACheckpointIsAUserError) {
  const fs::path dir = tempDir("resume_none");
  std::vector<std::string> a = runArgs(kCoupled, dir / "empty");
  a.push_back("--resume");
  CommandResult r = runMorphoflow(join(a));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find((dir / "empty" / "checkpoints").string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no checkpoint"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

TEST(Resume, ADamagedCheckpointFallsBackToTheOlderOne) {
  const fs::path dir = tempDir("resume_damaged");
  ResumeCase c = kCoupled;
  c.sets[2] = "time.steps=3000";
  ASSERT_EQ(runMorphoflow(join(runArgs(c, dir / "whole"))).status, 0);
  ASSERT_EQ(interruptAfterFirstCheckpoint(c, dir / "cut", SIGKILL), 128 + SIGKILL);
  // Wait for two checkpoints by resuming and stopping once more, then damage the newest.
  std::vector<std::string> resume = runArgs(c, dir / "cut");
  resume.push_back("--resume");
  const pid_t pid = startMorphoflow(resume, dir / "cut.log2");
  const size_t had = checkpoints(dir / "cut").size();
  ASSERT_TRUE(waitUntil([&] { return checkpoints(dir / "cut").size() > had || had >= 2; }, 120));
  if (pid > 0) kill(pid, SIGKILL);
  waitMorphoflow(pid);
  std::vector<fs::path> cps = checkpoints(dir / "cut");
  ASSERT_GE(cps.size(), 2u);
  fs::resize_file(cps.back(), fs::file_size(cps.back()) / 2);  // cut short
  CommandResult r = runMorphoflow(join(resume));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(cps.back().string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("unusable"), std::string::npos) << r.output;
  EXPECT_GT(expectSameFiles(dir / "whole", dir / "cut"), 4);
  // Every checkpoint damaged: an error naming the folder, nothing written.
  for (const fs::path& p : checkpoints(dir / "cut")) std::ofstream(p, std::ios::binary) << "MFCKPT01 garbage";
  r = runMorphoflow(join(resume));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("no checkpoint here is intact"), std::string::npos) << r.output;
  EXPECT_GT(expectSameFiles(dir / "whole", dir / "cut"), 4);
  fs::remove_all(dir);
}

namespace {

// A checkpoint file with its header and state changed by `edit`, checksummed
// as the program writes it (magic, header length, header, state length,
// state, XXH64).
void rewriteCheckpoint(const fs::path& file, const std::function<void(std::string* header, std::string* state)>& edit) {
  const std::string in = bytes(file);
  uint64_t hn = 0, sn = 0;
  std::memcpy(&hn, in.data() + 8, 8);
  std::memcpy(&sn, in.data() + 16 + hn, 8);
  std::string header = in.substr(16, hn), state = in.substr(24 + hn, sn);
  edit(&header, &state);
  std::string out = in.substr(0, 8);
  for (const std::string* part : {&header, &state}) {
    const uint64_t n = part->size();
    out.append(reinterpret_cast<const char*>(&n), 8);
    out += *part;
  }
  const uint64_t digest = XXH64(out.data(), out.size(), 0);
  out.append(reinterpret_cast<const char*>(&digest), 8);
  std::ofstream(file, std::ios::binary | std::ios::trunc) << out;
}

void rewriteHeader(const fs::path& file, const std::string& header) {
  rewriteCheckpoint(file, [&](std::string* h, std::string*) { *h = header; });
}

}  // namespace

// A checkpoint whose checksum holds but whose header lacks what a resume
// reads (not an object, a key missing, a key of the wrong type, an output's
// state that is not a number), and one far larger than the memory (sparse),
// are unusable as a damaged one is: a warning naming it, and the older one
// used. Another version's checkpoint is used by the stated rule (every state
// section must fit), with a warning naming both versions.
TEST(Resume, AMalformedHeaderOrAHugeFileIsUnusableAndAnotherVersionIsSaidSo) {
  const fs::path dir = tempDir("resume_header");
  const std::vector<std::string> run = {"run",
                                        sceneFile("rd/gray_scott_pearson.toml"),
                                        "--set",
                                        "grid.resolution=[24,24]",
                                        "--set",
                                        "time.steps=6",
                                        "--set",
                                        "output.every=2",
                                        "--set",
                                        "output.checkpoint_every=1",
                                        "--quiet",
                                        "--out",
                                        (dir / "out").string()};
  ASSERT_EQ(runMorphoflow(join(run)).status, 0);
  std::vector<fs::path> cps = checkpoints(dir / "out");
  ASSERT_GE(cps.size(), 2u);
  const fs::path newest = cps.back(), saved = dir / "newest.ckpt";
  fs::copy_file(newest, saved);
  std::ifstream in(newest, std::ios::binary);
  std::string head(24, '\0');
  in.read(head.data(), 16);
  uint64_t hn = 0;
  std::memcpy(&hn, head.data() + 8, 8);
  head.resize(hn);
  in.read(head.data(), std::streamsize(hn));
  const nlohmann::json header = nlohmann::json::parse(head);
  std::vector<std::string> resume = run;
  resume.push_back("--resume");
  auto withHeader = [&](const std::function<void(nlohmann::json*)>& change) {
    nlohmann::json h = header;
    change(&h);
    fs::copy_file(saved, newest, fs::copy_options::overwrite_existing);
    rewriteHeader(newest, h.dump());
    return runMorphoflow(join(resume));
  };
  const std::vector<std::pair<std::string, std::function<void(nlohmann::json*)>>> malformed = {
      {"not an object", [](nlohmann::json* h) { *h = nlohmann::json::array({1, 2}); }},
      {"no sinks", [](nlohmann::json* h) { h->erase("sinks"); }},
      {"step a string", [](nlohmann::json* h) { (*h)["step"] = "x"; }},
      {"scene a number", [](nlohmann::json* h) { (*h)["scene"] = 3; }},
      {"sink state a string", [](nlohmann::json* h) { (*h)["sinks"][0]["written"] = "many"; }},
      {"sink state without its count", [](nlohmann::json* h) { (*h)["sinks"][0].erase("written"); }},
      {"sink state negative", [](nlohmann::json* h) { (*h)["sinks"][0]["bytes"] = -7; }},
  };
  for (const auto& [what, change] : malformed) {
    const CommandResult r = withHeader(change);
    EXPECT_EQ(r.status, 0) << what << "\n" << r.output;
    EXPECT_NE(r.output.find(newest.string()), std::string::npos) << what << "\n" << r.output;
    EXPECT_NE(r.output.find("the checkpoint is unusable: "), std::string::npos) << what << "\n" << r.output;
  }
  fs::copy_file(saved, newest, fs::copy_options::overwrite_existing);
  std::error_code ec;  // a sparse file far beyond any machine's memory (ext4 allows up to 16 TiB)
  for (int e = 43; e >= 40 && (fs::resize_file(newest, uintmax_t(1) << e, ec), ec); --e) {
  }
  ASSERT_FALSE(ec) << ec.message();
  CommandResult r = runMorphoflow(join(resume));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("more than the"), std::string::npos) << r.output;
  r = withHeader([](nlohmann::json* h) { (*h)["version"] = "0.0.1-other"; });
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("written by morphoflow 0.0.1-other"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("unusable"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// A checkpoint whose checksum holds but whose state holds NaN or infinity
// (in a species, in a double scalar such as the time), and one whose image
// output's state lacks the first frame it wrote, are refused with exit 2
// naming the file and the section or output: never a crash or a NaN run.
TEST(Resume, AStateHoldingNaNOrAnOutputStateLackingAKeyIsRefusedNamingIt) {
  const fs::path dir = tempDir("resume_state");
  const std::vector<std::string> run = {"run",
                                        sceneFile("rd/gray_scott_pearson.toml"),
                                        "--set",
                                        "grid.resolution=[24,24]",
                                        "--set",
                                        "time.steps=4",
                                        "--set",
                                        "output.every=2",
                                        "--set",
                                        "output.checkpoint_every=1",
                                        "--quiet",
                                        "--out",
                                        (dir / "out").string()};
  ASSERT_EQ(runMorphoflow(join(run)).status, 0);
  std::vector<fs::path> cps = checkpoints(dir / "out");
  ASSERT_FALSE(cps.empty());
  const fs::path newest = cps.back(), saved = dir / "newest.ckpt";
  fs::copy_file(newest, saved);
  std::vector<std::string> resume = run;
  resume.push_back("--resume");
  // The value at the start of a section's data: its frame is the name's
  // length (4 bytes), the name and the data's length (8 bytes).
  auto poison = [&](const std::string& section, double value) {
    fs::copy_file(saved, newest, fs::copy_options::overwrite_existing);
    rewriteCheckpoint(newest, [&](std::string*, std::string* state) {
      const size_t at = state->find(section);
      ASSERT_NE(at, std::string::npos) << section;
      std::memcpy(state->data() + at + section.size() + 8, &value, sizeof(double));
    });
    return runMorphoflow(join(resume));
  };
  for (const auto& [section, value] : std::vector<std::pair<std::string, double>>{
           {"rd.0.x", std::nan("")}, {"rd.1.x", -INFINITY}, {"rd.time", INFINITY}}) {
    const CommandResult r = poison(section, value);
    EXPECT_EQ(r.status, 2) << section << "\n" << r.output;
    EXPECT_NE(r.output.find(newest.string()), std::string::npos) << section << "\n" << r.output;
    EXPECT_NE(r.output.find("section '" + section + "' holds a non-finite value"), std::string::npos) << r.output;
  }
  fs::copy_file(saved, newest, fs::copy_options::overwrite_existing);
  rewriteCheckpoint(newest, [](std::string* header, std::string*) {
    nlohmann::json h = nlohmann::json::parse(*header);
    h["sinks"][0].erase("first_written");
    *header = h.dump();
  });
  const CommandResult r = runMorphoflow(join(resume));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(newest.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("state of output 1 is damaged"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("first_written"), std::string::npos) << r.output;
  fs::remove_all(dir);
}
