// The libraries above the solvers, in process: the simulation factory
// (sim/), the run driver and the output sinks (run/).
#include <gtest/gtest.h>

#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "render/field_dump.h"
#include "run/output_sinks.h"
#include "run/run_driver.h"
#include "run/run_log.h"
#include "run/run_options.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"
#include "test_support.h"

using namespace morphoflow;
using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

const auto quietLog = [](const std::string&) {};

// Every field of the simulation, in fieldNames() order, flattened.
template <int D>
std::vector<float> allFields(const Simulation<D>& sim) {
  std::vector<float> out;
  for (const std::string& name : sim.fieldNames())
    for (const Grid<float, D>& g : sim.field(name)) out.insert(out.end(), g.values().begin(), g.values().end());
  return out;
}

const std::vector<std::string> kSmallCoupled = {"grid.resolution=[32,32]", "rd.resolution=[64,64]", "output.video=false"};

}  // namespace

TEST(SimulationFactory, BackendNamesAreTheCommandLinesAndOthersAreRefused) {
  EXPECT_EQ(backendNamed("tbb"), Backend::TBB);
  EXPECT_EQ(backendNamed("serial"), Backend::Serial);
  EXPECT_EQ(backendNamed("gpu"), Backend::Gpu);
  EXPECT_THROW(backendNamed("cuda"), std::invalid_argument);
}

// The coupled step's two schedulers overlap the fluid's work with the
// reaction-diffusion's differently; the fields they reach are bitwise the same.
TEST(SimulationFactory, SerialAndTbbCoupledStepsGiveTheSameFields) {
  const Scene scene = loadScene(sceneFile("coupled/cavity_gray_scott.toml"), kSmallCoupled);
  auto serial = makeSimulation<2>(scene, Backend::Serial, quietLog, quietLog);
  auto tbb = makeSimulation<2>(scene, Backend::TBB, quietLog, quietLog);
  ASSERT_EQ(serial->fieldNames(), tbb->fieldNames());
  const std::vector<float> start = allFields(*tbb);
  for (int k = 0; k < 5; ++k) serial->step(scene.time.dt), tbb->step(scene.time.dt);
  const std::vector<float> a = allFields(*serial), b = allFields(*tbb);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, start) << "the steps changed the fields";
  EXPECT_EQ(tbb->steps(), 5);
}

// Each kind of scene gets the simulation that carries its fields: the
// species of a reaction-diffusion scene, the fluid's of a fluid scene, both
// for a coupled one.
TEST(SimulationFactory, EachKindOfSceneGetsItsFields) {
  auto has = [](const std::vector<std::string>& names, const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  const Scene rd = loadScene(sceneFile("rd/gray_scott_pearson.toml"), {"grid.resolution=[32,32]"});
  const auto rdNames = makeSimulation<2>(rd, Backend::TBB, quietLog, quietLog)->fieldNames();
  EXPECT_TRUE(has(rdNames, "u") && has(rdNames, "v"));
  EXPECT_FALSE(has(rdNames, "vorticity"));
  const Scene fluid = loadScene(sceneFile("lid_driven_cavity.toml"), {"grid.resolution=[32,32]"});
  const auto fluidNames = makeSimulation<2>(fluid, Backend::TBB, quietLog, quietLog)->fieldNames();
  EXPECT_TRUE(has(fluidNames, "vorticity"));
  EXPECT_FALSE(has(fluidNames, "u"));
  const Scene coupled = loadScene(sceneFile("coupled/cavity_gray_scott.toml"), kSmallCoupled);
  const auto both = makeSimulation<2>(coupled, Backend::TBB, quietLog, quietLog)->fieldNames();
  EXPECT_TRUE(has(both, "vorticity") && has(both, "v"));
}

// The driver writes frame 0 and one every output.every steps, field dumps
// that hold what the simulation holds at the end, and a run.json that says
// the run completed at the last step.
TEST(RunDriver, WritesEveryFrameAndTheFinalStateInProcess) {
  const fs::path dir = tempDir("driver_in_process");
  const Scene scene = loadScene(sceneFile("rd/gray_scott_pearson.toml"),
                                {"grid.resolution=[32,32]", "time.steps=12", "output.every=4", "output.fields=true",
                                 "output.video=false"});
  auto sim = makeSimulation<2>(scene, Backend::TBB, quietLog, quietLog);
  RunOptions opt;
  opt.out = dir.string();
  opt.quiet = true;
  RunLog log(true, false);
  ASSERT_EQ(driveRun<2>(*sim, scene, opt, &log), 0);
  EXPECT_EQ(sim->steps(), 12);
  for (int f = 0; f <= 3; ++f) {
    const std::string name = fmt::format("{:06d}", f);
    EXPECT_TRUE(fs::exists(dir / "frames" / (name + ".png"))) << name;
    EXPECT_TRUE(fs::exists(dir / "fields" / (name + ".exr"))) << name;
  }
  EXPECT_FALSE(fs::exists(dir / "frames" / "000004.png"));
  FieldDump d;
  std::string error;
  ASSERT_TRUE(readFieldDump((dir / "fields" / "000003.exr").string(), &d, &error)) << error;
  EXPECT_EQ(d.step, 12);
  for (size_t c = 0; c < d.names.size(); ++c) EXPECT_EQ(d.channels[c], sim->field(d.names[c]).front().values()) << d.names[c];
  std::ifstream in(dir / "run.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["exit_state"], "completed");
  fs::remove_all(dir);
}

// The sinks a scene's [output] asks for, fed one frame: each writes its file
// and reports its bytes.
TEST(OutputSinks, TheSceneChoosesTheSinksAndEachReportsWhatItWrote) {
  const fs::path dir = tempDir("sinks_in_process");
  const Scene scene = loadScene(sceneFile("rd/gray_scott_pearson.toml"),
                                {"grid.resolution=[32,32]", "output.fields=true", "output.normal_map=true", "output.video=false"});
  auto sim = makeSimulation<2>(scene, Backend::TBB, quietLog, quietLog);
  auto sinks = makeOutputSinks<2>(dir, scene, [] { return false; });
  EXPECT_EQ(sinks.size(), 3u) << "frames, field dumps and normal maps";
  nlohmann::json run;
  for (auto& s : sinks) {
    s->write(FrameInfo{0, 0, scene.time.dt}, *sim);
    s->finish();
    s->report(&run);
  }
  for (const char* f : {"frames/000000.png", "fields/000000.exr", "normals/000000.png", "height/000000.exr"})
    EXPECT_GT(fileBytes(dir / f), 0u) << f;
  uintmax_t reported = 0;
  for (const auto& [kind, bytes] : run["bytes_written"].items()) reported += bytes.get<uintmax_t>();
  EXPECT_GE(reported, fileBytes(dir / "frames/000000.png") + fileBytes(dir / "fields/000000.exr"));
  fs::remove_all(dir);
}
