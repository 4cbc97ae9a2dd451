// The libraries above the solvers, in process: the simulation factory
// (sim/), the run driver and the output sinks (run/).
#include <gtest/gtest.h>

#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/expression.h"
#include "sim/host_copy.h"
#include "core/sampling.h"
#include "gpu/gl_context.h"
#include "render/field_dump.h"
#include "run/output_sinks.h"
#include "run/run_driver.h"
#include "run/run_log.h"
#include "run/run_options.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"
#include "tests/test_support.h"

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

const std::vector<std::string> kSmallCoupled = {"grid.resolution=[32,32]", "rd.resolution=[64,64]",
                                                "output.video=false"};

// A checkpoint of `sim` after `before` steps, read into a fresh simulation of
// the scene; both then take `after` more: the fields must stay bitwise equal.
template <int D>
void expectResumesBitwise(const Scene& scene, Backend backend, int before, int after) {
  auto a = makeSimulation<D>(scene, backend, quietLog, quietLog);
  for (int k = 0; k < before; ++k) a->step(scene.time.dt);
  std::string bytes;
  StateWriter out([&](std::string_view frame, const void* data, size_t n) {
    bytes.append(frame);
    bytes.append(static_cast<const char*>(data), n);
  });
  a->save(&out);
  auto b = makeSimulation<D>(scene, backend, quietLog, quietLog);
  b->load(StateReader(std::move(bytes)));
  EXPECT_EQ(b->steps(), a->steps());
  EXPECT_EQ(b->time(), a->time());
  EXPECT_EQ(allFields(*b), allFields(*a));
  for (int k = 0; k < after; ++k) a->step(scene.time.dt), b->step(scene.time.dt);
  EXPECT_EQ(allFields(*b), allFields(*a)) << scene.path;
}

const std::vector<std::pair<std::string, std::vector<std::string>>> kEveryKind = {
    {"rd/turing_coarse_to_fine.toml",
     {"grid.resolution=[32,32]", "rd.coarse_to_fine.steps=3"}},  // the fused explicit step
    {"rd/gray_scott_pearson.toml", {"grid.resolution=[32,32]"}},
    {"lid_driven_cavity.toml", {"grid.resolution=[32,32]"}},
    {"coupled/cavity_gray_scott.toml", kSmallCoupled},
    {"vfx/plume_2d.toml",
     {"grid.resolution=[32,48]", "sources.0.motion=[\"0.5 + 0.1 * t\", \"0.15\"]"}},         // smoke, a moving source
    {"vfx/plume_gray_scott_2d.toml", {"grid.resolution=[32,48]", "rd.resolution=[64,96]"}},  // the pattern on the smoke
};

}  // namespace

// A number where an expression may stand (a given velocity's component, a
// source's motion) keeps every digit.
TEST(SceneLoad, ANumberGivenForAnExpressionKeepsEveryDigit) {
  const std::string base = "[grid]\nresolution = [16, 16]\n[time]\ndt = 0.01\nsteps = 2\n";
  const Scene given = parseScene(base + "[rd]\nmodel = \"gray-scott\"\n[rd.maps]\nF = 0.0123456789\n"
                                        "[velocity]\nfield = [0.123456789, 1e-7]\n", "v.toml");
  const Scene smoke = parseScene(base +
                                     "[fluid]\nviscosity = 0.0\n[[sources]]\nshape = \"circle\"\ncenter = [0.5, 0.5]\n"
                                     "radius = 0.1\ndensity = 1.0\nmotion = [0.123456789, 0.5]\n",
                                 "s.toml");
  const double at[4] = {0.3, 0.7, 0.0, 0.0};
  ASSERT_EQ(given.velocity.field.size(), 2u);
  EXPECT_EQ(Expression(given.velocity.field[0], {"x", "y", "z", "t"}).evaluate(at), 0.123456789);
  EXPECT_EQ(Expression(given.velocity.field[1], {"x", "y", "z", "t"}).evaluate(at), 1e-7);
  EXPECT_EQ(Expression(smoke.fluid.smoke.sources.at(0).motion.at(0), {"t"}).evaluate(at), 0.123456789);
  ASSERT_EQ(given.rd.parameterMaps.size(), 1u);
  EXPECT_EQ(Expression(given.rd.parameterMaps[0].second.field.expression, {"x", "y", "z", "t"}).evaluate(at),
            0.0123456789);
}

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
  for (size_t c = 0; c < d.names.size(); ++c)
    EXPECT_EQ(d.channels[c], sim->field(d.names[c]).front().values()) << d.names[c];
  std::ifstream in(dir / "run.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["exit_state"], "completed");
  fs::remove_all(dir);
}

// The sinks a scene's [output] asks for, fed one frame: each writes its file
// and reports its bytes.
TEST(OutputSinks, TheSceneChoosesTheSinksAndEachReportsWhatItWrote) {
  const fs::path dir = tempDir("sinks_in_process");
  const Scene scene =
      loadScene(sceneFile("rd/gray_scott_pearson.toml"),
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

// A host copy is refreshed once after each step that moved the state on, and
// never when nothing did.
TEST(HostCopy, RefreshesOnlyAfterAStepAndOnce) {
  int refreshes = 0;
  HostCopy copy([&] { ++refreshes; });
  copy.refresh();
  EXPECT_EQ(refreshes, 0);
  copy.stepped();
  copy.stepped();
  copy.refresh();
  copy.refresh();
  EXPECT_EQ(refreshes, 1);
  copy.stepped();
  copy.refresh();
  EXPECT_EQ(refreshes, 2);
}

// Every kind of scene, on each backend's steppers, resumes from its own
// checkpoint bitwise: the steppers' state and the hosts' together are the
// whole state.
TEST(Steppers, EveryKindOfSceneResumesBitwiseOnTheCpu) {
  for (const auto& [file, sets] : kEveryKind)
    expectResumesBitwise<2>(loadScene(sceneFile(file), sets), Backend::TBB, 3, 3);
}

TEST(Steppers, EveryKindOfSceneResumesBitwiseOnTheGpu) {
  if (const GpuInfo g = gpuInfo(); !g.available) GTEST_SKIP() << g.reason;
  for (const auto& [file, sets] : kEveryKind) {
    const Scene scene = loadScene(sceneFile(file), sets);
    checkBackend(scene, Backend::Gpu);
    expectResumesBitwise<2>(scene, Backend::Gpu, 3, 3);
  }
}

// The one choice of a layer's stepper: the plain explicit step fused on the
// CPU (float species) and in float on the GPU, every other step in double on
// the CPU and in the scene's gpu.precision on the GPU (float unless double);
// the same simulation class on both backends says which it took.
TEST(Steppers, TheLayerStepperFollowsTheSceneAndTheBackend) {
  const Scene plain =
      loadScene(sceneFile("rd/turing_coarse_to_fine.toml"), {"grid.resolution=[32,32]", "rd.coarse_to_fine.steps=3"});
  const Scene implicit = loadScene(sceneFile("rd/gray_scott_pearson.toml"), {"grid.resolution=[32,32]"});
  const Scene inDouble =
      loadScene(sceneFile("rd/gray_scott_pearson.toml"), {"grid.resolution=[32,32]", "gpu.precision=\"double\""});
  ASSERT_TRUE(plain.rd.plainExplicit());
  ASSERT_FALSE(implicit.rd.plainExplicit());
  auto step = [](const Scene& s, Backend b) {
    return makeSimulation<2>(s, b, quietLog, quietLog)->resolved()["explicit_step"].get<std::string>();
  };
  EXPECT_EQ(step(plain, Backend::TBB).rfind("fused", 0), 0u);
  EXPECT_EQ(step(implicit, Backend::TBB).rfind("RDSolver", 0), 0u);
  if (const GpuInfo g = gpuInfo(); !g.available) GTEST_SKIP() << g.reason;
  EXPECT_NE(step(plain, Backend::Gpu).find("float"), std::string::npos);
  EXPECT_NE(step(implicit, Backend::Gpu).find("float"), std::string::npos);
  EXPECT_NE(step(inDouble, Backend::Gpu).find("double"), std::string::npos);
}

// The pattern on the smoke (coupling.smoke_mask): after every step, an RD
// cell whose smoke (at its centre) is at most the mask holds the rest state
// exactly, the source's chemicals seed the layer inside it, and the pattern
// reacts within the plume; the serial and tbb schedules agree bitwise.
TEST(SmokeLayer, ThePatternLivesWhereThereIsSmokeAndRestsElsewhere) {
  const Scene scene = loadScene(sceneFile("vfx/plume_gray_scott_2d.toml"),
                                {"grid.resolution=[32,48]", "rd.resolution=[64,96]", "time.duration=0.6"});
  auto sim = makeSimulation<2>(scene, Backend::TBB, quietLog, quietLog);
  auto serial = makeSimulation<2>(scene, Backend::Serial, quietLog, quietLog);
  for (int k = 0; k < 60; ++k) sim->step(scene.time.dt), serial->step(scene.time.dt);
  EXPECT_EQ(allFields(*sim), allFields(*serial));
  const Grid<float, 2> u = sim->field("u").front(), v = sim->field("v").front(), smoke = sim->field("dye").front();
  const double mask = scene.coupling.smokeMask, rdH = 1.0 / 64, fluidH = 1.0 / 32;
  const Layout<2> layout = Layout<2>::cellCentred(fluidH, smoke.dims(), {false, false});
  int resting = 0, patterned = 0;
  float vmax = 0.0f;
  for (size_t i = 0; i < v.size(); ++i) {
    const IVec<2> k = v.coord(i);
    const Vec<2> x((k[0] + 0.5) * rdH, (k[1] + 0.5) * rdH);
    if (sampleLinear<float, 2>(smoke, layout, x) <= mask) {
      EXPECT_EQ(u[i], 1.0f) << k[0] << ", " << k[1];
      EXPECT_EQ(v[i], 0.0f) << k[0] << ", " << k[1];
      ++resting;
    } else {
      vmax = std::max(vmax, v[i]);
      ++patterned;
    }
  }
  EXPECT_GT(resting, int(v.size()) / 2) << "most of the box has no smoke";
  EXPECT_GT(patterned, 50);
  EXPECT_GT(vmax, 0.1f) << "the seeded pattern reacts inside the plume";
}
