// Input a hostile or careless user can give: every case is a clear error
// (exit 2, naming the file or key, at once), never a crash, a hang, a huge
// allocation or a NaN field.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <atomic>
#include <chrono>
#include <fstream>
#include <limits>
#include <thread>
#include <tuple>

#include <nlohmann/json.hpp>

#include "core/parallel.h"
#include "render/allocation_limit.h"
#include "render/contact_sheet.h"
#include "render/field_dump.h"
#include "render/image_io.h"
#include "render/vdb_volume.h"
#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

const char* const kRdScene = R"(name = "hostile"
[grid]
resolution = [32, 32]
[domain]
size = [0.5, 0.5]
[time]
dt = 1.0
steps = 20
[rd]
model = "gray-scott"
diffusion = [2e-5, 1e-5]
[rd.initial]
values = [1.0, 0.0]
square = 0.1
square_values = [0.5, 0.25]
[output]
every = 10
image_size = 32
)";

const char* const kFluidScene = R"(name = "cavity"
[grid]
resolution = [32, 32]
[time]
dt = 0.01
steps = 5
[fluid]
reynolds = 100
lid_velocity = 1.0
)";

fs::path write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

// Exit 2 within `seconds`, the output naming `expect`.
void expectUserError(const std::string& args, const std::string& expect, double seconds = 20) {
  const auto t0 = std::chrono::steady_clock::now();
  CommandResult r = runMorphoflow(args);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
  EXPECT_NE(r.output.find(expect), std::string::npos) << args << "\n" << r.output;
  EXPECT_LT(took, seconds) << args;
}

// A PNG whose header claims width x height (8-bit grey) and holds no pixels.
std::string pngHeader(uint32_t width, uint32_t height) {
  auto crc = [](const std::string& bytes) {
    uint32_t c = 0xffffffffu;
    for (unsigned char b : bytes) {
      c ^= b;
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
  };
  auto be = [](uint32_t v) { return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; };
  auto chunk = [&](const std::string& type, const std::string& data) {
    return be(uint32_t(data.size())) + type + data + be(crc(type + data));
  };
  return std::string("\x89PNG\r\n\x1a\n", 8) +
         chunk("IHDR", be(width) + be(height) + std::string("\x08\x00\x00\x00\x00", 5)) +
         chunk("IDAT", std::string("\x78\x9c\x03\x00\x00\x00\x00\x01", 8)) + chunk("IEND", "");
}

}  // namespace

TEST(HostileInput, ASceneThatIsAFolderADeviceOrAPipeIsRefusedAtOnce) {
  const fs::path dir = tempDir("hostile_paths");
  const fs::path fifo = dir / "scene.toml";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& path : {dir.string(), std::string("/dev/zero"), fifo.string()}) {
    expectUserError("run " + path + " --out " + (dir / "o").string(), "not a regular file", 5);
    expectUserError("validate " + path, "not a regular file", 5);
    expectUserError("batch " + path + " --out " + (dir / "b").string(), "not a regular file", 5);
  }
  // A file far larger than any scene is not read whole.
  {
    std::ofstream big(dir / "big.toml");
    big << "# " << std::string(5u << 20, 'x') << "\n";
  }
  expectUserError("validate " + (dir / "big.toml").string(), "larger than 4 MiB");
  fs::remove_all(dir);
}

TEST(HostileInput, QuantitiesThatSizeWorkAreBoundedBeforeUse) {
  const fs::path dir = tempDir("hostile_bounds");
  const std::string rd = write(dir / "rd.toml", kRdScene).string(),
                    fluid = write(dir / "fluid.toml", kFluidScene).string();
  // duration / dt steps
  const std::string o = " --quiet --out " + (dir / "o").string();
  expectUserError("run " + rd + o + " --set time.steps=0", "time.steps");
  CommandResult r = runMorphoflow("run " + rd + " --quiet --out " + (dir / "o").string() +
                                  " --set 'time={dt=1e-300,duration=1e9}'");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("steps, more than 100000000"), std::string::npos) << r.output;
  // a CFL limit whose steps would never end: refused at the step it sets dt, naming time.cfl
  r = runMorphoflow("run " + fluid + o + " --set 'time={dt=0.01,duration=1.0,cfl=1e-12}'");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("'time.cfl'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("more than 100000000"), std::string::npos) << r.output;
  // memory that ulimit -v does not give: refused before allocating, with what is available
  std::string out;
  {
    const std::string cmd = "ulimit -v 1200000; " + std::string(MORPHOFLOW_BINARY) + " run " +
                            sceneFile("coupled/cavity_gray_scott_3d.toml") + " --set time.steps=2" + o + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    char buf[4096];
    for (size_t n; p && (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    const int st = p ? pclose(p) : -1;
    EXPECT_EQ(WIFEXITED(st) ? WEXITSTATUS(st) : -1, 2) << out;
  }
  // the figure `validate` gives the scene (the same estimate)
  const std::string v = runMorphoflow("validate " + sceneFile("coupled/cavity_gray_scott_3d.toml")).output;
  const size_t at = v.find("needs about "), end = v.find(" of memory", at);
  ASSERT_NE(end, std::string::npos) << v;
  EXPECT_NE(out.find("this run " + v.substr(at, end - at) + " of memory, and"), std::string::npos) << out << v;
  EXPECT_EQ(out.find("internal error"), std::string::npos) << out;
  // a viscosity from a tiny Reynolds number
  expectUserError("run " + fluid + " --quiet --set fluid.reynolds=1e-300 --out " + (dir / "o").string(),
                  "fluid.reynolds");
  // cells so small that back-traces lose all precision, and back-traces a million cells long
  expectUserError("run " + fluid + " --quiet --set domain.size=[1e-12,1e-12] --out " + (dir / "o").string(),
                  "domain.size");
  expectUserError(
      "run " + fluid + " --quiet --set fluid.lid_velocity=1e6 --set time.dt=1 --out " + (dir / "o").string(),
      "time.dt");
  // bench sizes
  for (const char* size : {"0", "1", "-3", "2x", "16384"})
    expectUserError(std::string("bench rd --size ") + size, "size");
  // expressions: thousands of nested parentheses, and a very long one
  const std::string deep = std::string(2400, '(') + "x" + std::string(2400, ')');
  expectUserError("run " + rd + o + " --set 'rd.maps.F=\"" + deep + "\"'", "nested more than 200 deep");
  std::string longExpr = "x";
  for (int i = 0; i < 6000; ++i) longExpr += "+x";
  expectUserError("run " + rd + o + " --set 'rd.maps.F=\"" + longExpr + "\"'", "longer than 10000 characters");
  fs::remove_all(dir);
}

TEST(HostileInput, AnImageIsCheckedByItsHeaderBeforeItIsDecoded) {
  const fs::path dir = tempDir("hostile_images");
  const fs::path huge = write(dir / "huge.png", pngHeader(100000, 100000));
  expectUserError("analyze " + huge.string(), "claims 100000 x 100000", 5);
  const std::string rd = write(dir / "rd.toml", kRdScene).string();
  expectUserError("run " + rd + " --out " + (dir / "o").string() + " --set 'rd.maps.F={image=\"" + huge.string() +
                      "\",range=[0.02,0.05]}'",
                  "claims 100000 x 100000", 5);
  // Degenerate images for analyze: 1 x 1, and constant.
  const fs::path one = write(dir / "one.png", "");
  CommandResult made = runMorphoflow("texton --size 1 --elements 1 --steps 0 --out " + one.string());
  ASSERT_EQ(made.status, 0) << made.output;
  expectUserError("analyze " + one.string(), "at least 4 x 4");
  CommandResult flat =
      runMorphoflow("run " + rd + " --quiet --set 'rd.initial={values=[1.0,0.0]}' --set output.every=20 --out " +
                    (dir / "flat").string());
  ASSERT_EQ(flat.status, 0) << flat.output;
  expectUserError("analyze " + (dir / "flat" / "frames" / "000000.png").string(), "constant");
  fs::remove_all(dir);
}

TEST(HostileInput, NoFluidLeftIsRefusedAndAnUnconvergedPressureIsAWarning) {
  const fs::path dir = tempDir("hostile_fluid");
  const std::string fluid = write(dir / "fluid.toml", std::string(kFluidScene) +
                                  "[[obstacles]]\nshape = \"box\"\ncenter = [0.5, 0.5]\nsize = [2, 2]\n").string();
  expectUserError("run " + fluid + " --quiet --out " + (dir / "o").string(), "no fluid is left");
  // An obstacle over the whole inflow side lets nothing in (fluid and coupled scenes).
  for (const auto& [scene, box, side] :
       {std::tuple{sceneFile("flow_past_obstacle.toml") + " --set grid.resolution=[220,41] --set time.duration=0.02",
                   std::string("center=[0.02,0.2],size=[0.04,2.0]"), std::string("(low x)")},
        std::tuple{sceneFile("coupled/obstacle_gray_scott_ard.toml") +
                       " --set grid.resolution=[32,64] --set rd.resolution=[32,64] --set time.steps=2",
                   std::string("center=[0.4,1.58],size=[2.0,0.04]"), std::string("(high y)")}})
    expectUserError(
        "run " + scene + " --quiet --set 'obstacles=[{shape=\"box\"," + box + "}]' --out " + (dir / "o").string(),
        "cover the whole inflow side " + side);
  const std::string cavity = write(dir / "cavity.toml", kFluidScene).string();
  for (const std::string& args :
       {cavity, sceneFile("coupled/cavity_gray_scott.toml") +
                    " --set grid.resolution=[32,32] --set rd.resolution=[32,32] --set time.steps=3"}) {
    CommandResult r =
        runMorphoflow("run " + args + " --quiet --set fluid.pressure_max_iterations=1 --out " + (dir / "u").string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("warning: step 1: pressure solve stopped"), std::string::npos) << r.output;
    std::ifstream in(dir / "u" / "run.json");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    EXPECT_GT(j["solvers"]["pressure_unconverged_steps"].get<long>(), 0) << j.dump();
  }
  fs::remove_all(dir);
}

// An explicit step far beyond its stability limit: the run stops at the
// first check that sees it, naming the step, the stage and the stable dt;
// the frames and checkpoints written before stay.
TEST(HostileInput, ADivergingRunStopsNamingTheStepAndStageAndKeepsItsFrames) {
  const fs::path dir = tempDir("hostile_diverge");
  const std::string rd = write(dir / "rd.toml", kRdScene).string();
  for (const auto& [scene, sets, stage] :
       {std::tuple{rd, std::string(" --set time.dt=50"), std::string("in the explicit reaction-diffusion step")},
        std::tuple{
            sceneFile("coupled/cavity_gray_scott.toml"),
            std::string(
                " --set grid.resolution=[32,32] --set rd.resolution=[32,32] --set time.dt=0.2 --set time.steps=100"),
            std::string("in the advection-reaction-diffusion step")}}) {
    const fs::path out = dir / "o";
    fs::remove_all(out);
    CommandResult r = runMorphoflow("run " + scene + sets +
                                    " --quiet --set 'rd.integrator=\"explicit\"' --set output.every=1"
                                    " --set output.checkpoint_every=1 --out " +
                                    out.string());
    ASSERT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("diverged"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(stage), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("limit for this diffusion is time.dt = "), std::string::npos) << r.output;
    std::ifstream in(out / "run.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["exit_state"], "diverged");
    const long frames = j["frames_written"];
    int onDisk = 0;
    for (const auto& e : fs::directory_iterator(out / "frames")) onDisk += e.is_regular_file();
    EXPECT_EQ(onDisk, frames);
    EXPECT_GE(frames, 1);
  }
  fs::remove_all(dir);
}

// A run that blows up while staying finite (a speed past 1000 domain lengths
// and 1000 times the scene's own speeds per unit time) stops as a diverged
// one does: exit 2 naming the stage and the forces set, its frames kept.
TEST(HostileInput, ARunThatBlowsUpWhileFiniteStopsNamingTheForces) {
  const fs::path dir = tempDir("hostile_blowup");
  for (const auto& [scene, sets, key] :
       {std::tuple{sceneFile("vfx/plume_3d.toml"),
                   std::string(" --set grid.resolution=[12,20,12] --set smoke.vorticity=1e6"),
                   std::string("smoke.vorticity = 1e+06")},
        std::tuple{sceneFile("vfx/plume_2d.toml"),
                   std::string(" --set grid.resolution=[32,48] --set smoke.buoyancy=1e9"),
                   std::string("smoke.buoyancy = 1e+09")},
        std::tuple{sceneFile("vfx/plume_2d.toml"),
                   std::string(" --set grid.resolution=[32,48] --set smoke.weight=-1e9"),
                   std::string("smoke.weight = -1e+09")}}) {
    const fs::path out = dir / "o";
    fs::remove_all(out);
    CommandResult r = runMorphoflow("run " + scene + sets +
                                    " --quiet --set time.duration=0.5 --set output.every=2 --out " + out.string());
    ASSERT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("blew up"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("in the fluid step"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(key), std::string::npos) << r.output;
    std::ifstream in(out / "run.json");
    EXPECT_EQ(nlohmann::json::parse(in)["exit_state"], "diverged");
  }
  fs::remove_all(dir);
}

// Every numeric option is range-checked where it is parsed: infinities, NaN,
// values far beyond what the option can use, signs and empty tokens are exit
// 2 naming the option, before anything runs or is written.
TEST(HostileInput, CommandLineNumbersOutsideTheirRangeAreRefused) {
  const fs::path dir = tempDir("hostile_ranges");
  const std::string rd = write(dir / "rd.toml", kRdScene).string(), out = " --out " + (dir / "o").string();
  const std::string gen = sceneFile("rd/seeds/mcgraw_fig2_turing.toml"), png = " --out " + (dir / "p.png").string();
  std::vector<std::pair<std::string, std::string>> cases;  // the command, the option its error names
  for (const char* v : {"inf", "nan", "1e300", "1e-300", "-1"}) {
    cases.push_back({"plot propagator " + gen + " --tau " + v + png, "--tau"});
    cases.push_back({"plot propagator " + gen + " --radius " + v + png, "--radius"});
  }
  for (const char* v : {"inf", "nan", "1e9", "-1"})
    cases.push_back({std::string("bench roofline --seconds ") + v, "--seconds"});
  for (const char* v : {"inf", "nan", "1e9", "-1", "2.5"})
    cases.push_back({std::string("bench fluid --warm-up ") + v, "--warm-up"});
  for (const char* v : {"inf", "nan", "1e300", "-1"}) {
    cases.push_back({std::string("texton --lifetime ") + v + png, "--lifetime"});
    cases.push_back({std::string("texton --radius ") + v + png, "--radius"});
    cases.push_back({std::string("texton -p ") + v + png, "-p"});
  }
  for (const char* v : {"''", "+0/2", "0/+2", "-0/2", "0/2/3"})
    cases.push_back({"batch " + rd + " --shard " + v + out, "--shard"});
  for (const auto& [args, option] : cases) {
    CommandResult r = runMorphoflow(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(option), std::string::npos) << args << ": the option is not named\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "p.png"));
  EXPECT_FALSE(fs::exists(dir / "o"));
  fs::remove_all(dir);
}

// A run that would do nothing says so instead of exiting 0 in silence:
// --frames starting beyond the last frame (20 steps, a frame every 10: frames
// 0 to 2), a duration too short for a single step. The frames it can write still run.
TEST(HostileInput, ARunThatWouldDoNothingSaysSo) {
  const fs::path dir = tempDir("hostile_nothing");
  const std::string rd = write(dir / "rd.toml", kRdScene).string(), out = " --out " + (dir / "o").string();
  CommandResult r = runMorphoflow("run " + rd + " --frames 3:5 --quiet" + out);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("last frame, 2"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "o" / "frames"));
  r = runMorphoflow("run " + rd + " --frames 2:5 --quiet" + out);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "o" / "frames" / "000002.png"));
  std::string tiny = kRdScene;
  tiny.replace(tiny.find("steps = 20"), 10, "duration = 1e-13");
  r = runMorphoflow("run " + write(dir / "tiny.toml", tiny).string() + " --quiet" + out);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("time.duration"), std::string::npos) << r.output;
  // A source that covers no fluid cell (far smaller than a cell, or inside an
  // obstacle) runs, and says it emits nothing; the plume as shipped does not.
  const std::string plume =
      "run " + sceneFile("vfx/plume_2d.toml") + " --quiet --set grid.resolution=[32,48] --set time.duration=0.1" + out;
  // An obstacle between the faces of one cell is not seen by the flow: said; one smaller than a cell
  // that holds a cell's centre or crosses a face is seen, and nothing is said.
  const std::string channel = "run " + sceneFile("flow_past_obstacle.toml") +
                              " --quiet --set grid.resolution=[220,41] --set time.duration=0.02" + out;
  for (const auto& [obstacle, unseen] :
       {std::pair{std::string("{center=[0.203,0.203],radius=0.002}"), true},
        std::pair{std::string("{center=[0.203,0.203],radius=0.002,boundary=\"voxel\"}"), true},
        std::pair{std::string("{center=[0.205,0.205],radius=0.003}"), false},
        std::pair{std::string("{center=[0.2,0.205],radius=0.004}"), false}}) {
    r = runMorphoflow(channel + " --set 'obstacles=[" + obstacle + "]'");
    EXPECT_EQ(r.status, 0) << obstacle << ": " << r.output;
    EXPECT_EQ(r.output.find("obstacles.0 meets no cell centre or face") != std::string::npos, unseen)
        << obstacle << ": " << r.output;
  }
  // An image source's motion or center would move nothing: refused where it is written.
  const std::string fish = sceneFile("rd/seeds/images/fish.png");
  for (const std::string& extra : {std::string("center=[0.3,0.3]"), std::string("motion=[\"0.5\",\"t\"]")}) {
    r = runMorphoflow(plume + " --set 'sources=[{shape=\"image\",file=\"" + fish + "\",density=1.0," + extra + "}]'");
    EXPECT_EQ(r.status, 2) << extra << ": " << r.output;
    EXPECT_NE(r.output.find(extra.substr(0, extra.find('=')) == "center" ? "a center does not apply"
                                                                         : "a motion would move nothing"),
              std::string::npos)
        << r.output;
  }
  for (const std::string& sets : {std::string(" --set sources.0.radius=0.001"),
                                  std::string(" --set 'obstacles=[{center=[0.5,0.15],radius=0.2}]'"), std::string()}) {
    r = runMorphoflow(plume + sets);
    EXPECT_EQ(r.status, 0) << sets << ": " << r.output;
    EXPECT_EQ(r.output.find("sources.0 covers no fluid cell") != std::string::npos, !sets.empty())
        << sets << ": " << r.output;
  }
  fs::remove_all(dir);
}

// One rule for every sdf: a NaN or infinite distance is refused at the file
// (it would be read as no solid), a finite one that is solid everywhere is
// refused as covering every cell.
TEST(HostileInput, AnSdfIsFiniteOrRefusedAndOneSolidEverywhereLeavesNoFluid) {
  const fs::path dir = tempDir("hostile_sdf");
  const std::string cavity = "run " + sceneFile("lid_driven_cavity.toml") +
                             " --quiet --set grid.resolution=[16,16] --set time.duration=0.02 --out " +
                             (dir / "o").string();
  for (const auto& [value, expect] :
       {std::pair{-std::numeric_limits<float>::infinity(), std::string("the sdf holds -inf at pixel (0, 0)")},
        std::pair{std::numeric_limits<float>::quiet_NaN(), std::string("the sdf holds nan at pixel (0, 0)")},
        std::pair{-1.0f, std::string("the obstacles cover every cell")}}) {
    morphoflow::FieldDump d;
    d.resolution = {16, 16};
    d.names = {"Y"};
    d.channels = {std::vector<float>(256, value)};
    const std::string file = (dir / "sdf.exr").string();
    std::string error;
    ASSERT_TRUE(morphoflow::writeFieldDump(file, d, &error)) << error;
    CommandResult r = runMorphoflow(cavity + " --set 'obstacles=[{shape=\"sdf\",file=\"" + file + "\"}]'");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(expect), std::string::npos) << r.output;
  }
  fs::remove_all(dir);
}

// A given velocity that is not finite where it is read (an expression's
// division by zero, a logarithm of a negative number, a value beyond float
// range, one that blows up later in time) stops the run with exit 2 naming
// the [velocity] key, the component, the face and the time: never a crash.
TEST(HostileInput, AGivenVelocityThatIsNotFiniteIsRefusedWhereItIsRead) {
  const fs::path dir = tempDir("hostile_velocity");
  for (const auto& [u, when] : {std::pair{"1 / (x - x)", "t = 0"}, std::pair{"log(-1 - x)", "t = 0"},
                                std::pair{"1e300", "t = 0"}, std::pair{"1 / (1 - t)", "t = 1"}}) {
    std::string scene = kRdScene;
    scene.replace(scene.find("dt = 1.0"), 8, "dt = 0.5");
    scene += std::string("[velocity]\nfield = [\"") + u + "\", \"0\"]\n";
    const std::string file = write(dir / "v.toml", scene).string();
    const CommandResult r = runMorphoflow("run " + file + " --quiet --out " + (dir / "o").string());
    EXPECT_EQ(r.status, 2) << u << "\n" << r.output;
    EXPECT_NE(r.output.find(file + ":"), std::string::npos) << u << ": no location\n" << r.output;
    EXPECT_NE(r.output.find("velocity's u component"), std::string::npos) << u << "\n" << r.output;
    EXPECT_NE(r.output.find(when), std::string::npos) << u << "\n" << r.output;
  }
  fs::remove_all(dir);
}

// A stroke from a uniform image has cells under it but no edges, so no
// direction: it deposits (no direction needed), and where a direction is
// needed (lobes along the strokes) the run is exit 2 naming the stroke.
TEST(HostileInput, AStrokeFromAUniformImageDepositsButGivesNoDirection) {
  const fs::path dir = tempDir("hostile_uniform_stroke");
  std::ofstream(dir / "bright.pgm", std::ios::binary) << "P5 16 16 255\n" << std::string(256, char(255));
  const std::string base = std::string(kRdScene) + "[[rd.strokes]]\nimage = \"bright.pgm\"\n";
  CommandResult r =
      runMorphoflow("run " + write(dir / "deposit.toml", base + "species = [\"v\"]\nvalues = [0.5]\n").string() +
                    " --quiet --out " + (dir / "a").string());
  EXPECT_EQ(r.status, 0) << r.output;
  const std::string lobes =
      write(dir / "lobes.toml", base + "[rd.cosine_lobes]\nspeeds = [1]\ntheta0 = \"strokes\"\n").string();
  r = runMorphoflow("run " + lobes + " --quiet --out " + (dir / "b").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(lobes + ":"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the strokes give no direction"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "b" / "frames"));
  fs::remove_all(dir);
}

// A run never destroys its inputs: a scene that reads a file inside --out
// (here a map taken from an earlier run's frame) is refused naming the key
// before anything is deleted; the same scene into another folder runs.
TEST(HostileInput, ASceneThatReadsFromItsOutputFolderIsRefused) {
  const fs::path dir = tempDir("hostile_inputs_inside");
  const fs::path out = dir / "o";
  ASSERT_EQ(runMorphoflow("run " + write(dir / "rd.toml", kRdScene).string() + " --quiet --out " + out.string()).status,
            0);
  ASSERT_TRUE(fs::exists(out / "frames" / "000000.png"));
  const std::string mapped = write(dir / "mapped.toml", std::string(kRdScene) + "[rd.maps]\nF = { image = \"" +
                                                            (out / "frames" / "000000.png").string() +
                                                            "\", range = [0.03, 0.05] }\n")
                                 .string();
  CommandResult r = runMorphoflow("run " + mapped + " --quiet --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("rd.maps.F.image"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("inside the output folder"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(out / "frames" / "000000.png")) << "the input was deleted";
  r = runMorphoflow("run " + mapped + " --quiet --out " + (dir / "elsewhere").string());
  EXPECT_EQ(r.status, 0) << r.output;
  fs::remove_all(dir);
}

// Every file a command writes goes through the checked output path: for
// bench --json, plot --out, texton --out and analyze --csv, a folder, a FIFO
// (never opened: no hang) and a path under /dev are exit 2 naming the path
// before any work; so is a symlink (never written through); a missing
// folder is created.
TEST(HostileInput, EveryWriterRefusesFoldersPipesAndDevices) {
  const fs::path dir = tempDir("hostile_writers");
  const std::string gen = sceneFile("rd/seeds/mcgraw_fig2_turing.toml");
  const fs::path folder = dir / "folder", fifo = dir / "fifo";
  fs::create_directories(folder);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  const std::string png = (dir / "t.png").string();
  ASSERT_EQ(runMorphoflow("texton --size 32 --elements 4 --steps 4 --out " + png).status, 0);
  auto commands = [&](const std::string& target) {
    return std::vector<std::string>{
        "bench roofline --json " + target, "plot propagator " + gen + " --size 64 --out " + target,
        "texton --size 32 --elements 4 --steps 4 --out " + target, "analyze " + png + " --csv " + target};
  };
  for (const std::string& target : {folder.string(), fifo.string(), std::string("/dev/morphoflow_test_file")})
    for (const std::string& cmd : commands(target)) {
      const CommandResult r = runMorphoflow(cmd);
      EXPECT_EQ(r.status, 2) << cmd << "\n" << r.output;
      EXPECT_NE(r.output.find(target.rfind("/dev/", 0) == 0 ? std::string("/dev") : target), std::string::npos)
          << cmd << "\n"
          << r.output;
    }
  EXPECT_FALSE(fs::exists("/dev/morphoflow_test_file"));
  struct stat st;
  ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  // A symlink at the path is refused as any other non-file is: never written through.
  std::ofstream(dir / "target.txt") << "mine";
  fs::create_symlink(dir / "target.txt", dir / "link.png");
  EXPECT_EQ(runMorphoflow("texton --size 32 --elements 4 --steps 4 --out " + (dir / "link.png").string()).status, 2);
  EXPECT_TRUE(fs::is_symlink(dir / "link.png"));
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(std::ifstream(dir / "target.txt").rdbuf()), {}), "mine");
  // A missing folder is created.
  EXPECT_EQ(runMorphoflow("plot propagator " + gen + " --size 64 --out " + (dir / "new" / "p.png").string()).status, 0);
  EXPECT_TRUE(fs::is_regular_file(dir / "new" / "p.png"));
  fs::remove_all(dir);
}

// A run limited by --frames and then resumed without the limit writes every
// later frame, bitwise the frames of a run that was never limited.
TEST(HostileInput, ARunLimitedByFramesResumesWithTheNextFrame) {
  const fs::path dir = tempDir("hostile_frames_resume");
  const std::string rd = write(dir / "rd.toml", kRdScene).string() + " --set time.steps=50 --quiet --out ";
  ASSERT_EQ(runMorphoflow("run " + rd + (dir / "whole").string()).status, 0);
  ASSERT_EQ(runMorphoflow("run " + rd + (dir / "cut").string() + " --frames 0:2").status, 0);
  EXPECT_FALSE(fs::exists(dir / "cut" / "frames" / "000003.png"));
  ASSERT_EQ(runMorphoflow("run " + rd + (dir / "cut").string() + " --resume").status, 0);
  auto bytes = [](const fs::path& p) {
    return std::string(std::istreambuf_iterator<char>(std::ifstream(p, std::ios::binary).rdbuf()), {});
  };
  for (const char* f : {"000000.png", "000002.png", "000003.png", "000004.png", "000005.png"}) {
    ASSERT_TRUE(fs::exists(dir / "cut" / "frames" / f)) << f << " lost";
    EXPECT_EQ(bytes(dir / "cut" / "frames" / f), bytes(dir / "whole" / "frames" / f)) << f;
  }
  fs::remove_all(dir);
}

TEST(HostileInput, CommandLineNumbersAreWholeTokens) {
  const fs::path dir = tempDir("hostile_cli");
  const std::string rd = write(dir / "rd.toml", kRdScene).string(), out = " --out " + (dir / "o").string();
  for (const std::string& args : {"run " + rd + " --frames 1x:2y" + out, "run " + rd + " --frames 1:2y" + out,
                                  "run " + rd + " --frames ' 1:2'" + out, "run " + rd + " --threads 2x" + out,
                                  "batch " + rd + " --shard 1/2x" + out, "batch " + rd + " --shard ' 0/2'" + out,
                                  "batch " + rd + " --jobs 2x" + out, "analyze " + rd + " --max-lag 3q"}) {
    CommandResult r = runMorphoflow(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
  }
  fs::remove_all(dir);
}

// Inside an AllocationLimit, on its thread, one request above the bound is
// bad_alloc at once; below it, after the scope and on other threads, nothing changes.
TEST(HostileInput, AnAllocationLimitRefusesOneRequestAboveItsBoundOnlyInItsScope) {
  // (a direct call: a new-expression whose result is unused may be elided)
  auto allocate = [](size_t bytes) { ::operator delete(::operator new(bytes)); };
  {
    morphoflow::AllocationLimit limit(1 << 20);
    EXPECT_THROW(allocate(size_t(2) << 20), std::bad_alloc);
    EXPECT_NO_THROW(allocate(size_t(1) << 19));
    std::thread other([&] { EXPECT_NO_THROW(allocate(size_t(4) << 20)); });
    other.join();
  }
  EXPECT_NO_THROW(allocate(size_t(4) << 20));
}

// Volumes whose stored lengths claim gigabytes (a Blosc block, a metadata
// string: cases the fuzzer found) are refused as damaged without reading
// them into memory.
TEST(HostileInput, AVolumeWhoseLengthsClaimGigabytesIsRefusedAsDamaged) {
  for (const char* name : {"blosc_size_beyond_memory", "metadata_of_gigabytes", "metadata_copied"}) {
    const std::string file = std::string(MORPHOFLOW_SOURCE_DIR) + "/fuzz/regressions/vdb_velocity/" + name;
    morphoflow::VelocityVolume v;
    std::string error;
    EXPECT_FALSE(morphoflow::readVdbVelocity(file, &v, &error)) << name;
    EXPECT_FALSE(error.empty()) << name;
  }
}

namespace {

// A cell-centred velocity grid `vel` of `cells`, component a of cell i being
// 1 + a + slope i.
morphoflow::VolumeGrid velocityGrid(const std::array<int, 3>& cells, float slope) {
  morphoflow::VolumeGrid g;
  g.name = "vel";
  g.kind = morphoflow::VolumeGrid::Kind::Vector;
  g.cells = cells;
  g.values.assign(3, std::vector<float>(size_t(cells[0]) * size_t(cells[1]) * size_t(cells[2])));
  for (size_t a = 0; a < 3; ++a)
    for (size_t i = 0; i < g.values[a].size(); ++i) g.values[a][i] = 1.0f + float(a) + slope * float(i);
  return g;
}

}  // namespace

// A volume read while TBB's workers are busy is read: a run reads its next
// velocity frame between the parallel loops of its steps, and its reader
// (a program of its own) must not wait on a lock a worker holds.
TEST(HostileInput, AVolumeReadWhileTbbWorkersAreBusyIsRead) {
  const fs::path dir = tempDir("read_while_busy");
  const morphoflow::VolumeGrid g = velocityGrid({12, 10, 8}, 1e-3f);
  const std::string file = (dir / "vel.vdb").string();
  std::ofstream(file, std::ios::binary) << morphoflow::encodeVdb({g}, {}, {});
  std::atomic<bool> stop{false};
  std::thread busy([&] {
    while (!stop)
      morphoflow::parallelFor(
          64,
          [](size_t i) {
            volatile double x = double(i);
            for (int k = 0; k < 2000; ++k) x = x * 0.5 + 1.0;
          },
          1);
  });
  for (int i = 0; i < 40; ++i) {
    morphoflow::VelocityVolume v;
    morphoflow::VdbFrameSummary summary;
    std::string error;
    ASSERT_TRUE(morphoflow::readVdbVelocity(file, &v, &error)) << "read " << i << ": " << error;
    ASSERT_EQ(v.values[2].size(), g.values[2].size());
    EXPECT_EQ(v.values[2][7], g.values[2][7]);
    std::vector<morphoflow::VdbTime> times;
    size_t failed = 0;
    ASSERT_TRUE(morphoflow::readVdbTimes({file, file}, &times, &failed, &error)) << "read " << i << ": " << error;
    ASSERT_EQ(times.size(), 2u);
    ASSERT_TRUE(morphoflow::readVdbFrameSummary(file, &summary, &error)) << "read " << i << ": " << error;
  }
  stop = true;
  busy.join();
  fs::remove_all(dir);
}

// A long sequence's times are read by a reader for each 256 files, and a
// damaged file among them is named by its index; the times before it are kept.
TEST(HostileInput, ALongSequencesTimesAreReadAndItsDamagedFileNamed) {
  const fs::path dir = tempDir("long_sequence");
  const morphoflow::VolumeGrid g = velocityGrid({2, 2, 2}, 0.0f);
  std::vector<std::string> paths;
  for (int i = 0; i < 300; ++i) {
    morphoflow::VolumeMetadata meta;
    meta.time = 0.25 * i;
    paths.push_back((dir / ("vel." + std::to_string(1000 + i) + ".vdb")).string());
    std::ofstream(paths.back(), std::ios::binary) << morphoflow::encodeVdb({g}, meta, {});
  }
  std::vector<morphoflow::VdbTime> times;
  size_t failed = 0;
  std::string error;
  ASSERT_TRUE(morphoflow::readVdbTimes(paths, &times, &failed, &error)) << error;
  ASSERT_EQ(times.size(), paths.size());
  for (size_t i = 0; i < times.size(); ++i) EXPECT_TRUE(times[i].has && times[i].time == 0.25 * double(i)) << i;
  std::ofstream(paths[280], std::ios::binary) << "not a volume";
  EXPECT_FALSE(morphoflow::readVdbTimes(paths, &times, &failed, &error));
  EXPECT_EQ(failed, 280u) << error;
  EXPECT_EQ(times.size(), 280u);
  EXPECT_FALSE(error.empty());
  fs::remove_all(dir);
}

// A sweep's contact sheet shows a frame that cannot be read as a grey cell
// and names it; the sheet is still written.
TEST(HostileInput, AContactSheetShowsADamagedFrameGreyAndNamesIt) {
  const fs::path dir = tempDir("sheet_damaged_frame");
  std::string error;
  const std::string good = (dir / "good.png").string(), bad = (dir / "bad.png").string();
  ASSERT_TRUE(morphoflow::writeRgb8(good, 8, 8, std::vector<uint8_t>(192, 100), &error)) << error;
  ASSERT_TRUE(morphoflow::writeRgb8(bad, 8, 8, std::vector<uint8_t>(192, 200), &error)) << error;
  fs::resize_file(bad, fs::file_size(bad) / 2);
  morphoflow::ContactSheet sheet;
  sheet.columns = {"a", "b"};
  sheet.rows = {""};
  sheet.images = {good, bad};
  const std::vector<std::string> unread = morphoflow::writeContactSheet((dir / "sheet.png").string(), sheet);
  ASSERT_EQ(unread.size(), 1u);
  EXPECT_EQ(unread[0].rfind(bad, 0), 0u) << unread[0];
  morphoflow::GrayImage back;
  EXPECT_TRUE(morphoflow::readGrayImage((dir / "sheet.png").string(), &back, &error)) << error;
  fs::remove_all(dir);
}
