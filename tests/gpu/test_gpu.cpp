// --backend gpu: the explicit reaction-diffusion step on the GPU (llvmpipe in
// CI) against the CPU backend, 2D and 3D, periodic and zero-flux; the stages
// it has no program for are refused naming them; info and run.json name the
// renderer. Without an OpenGL 4.3 context the parity tests skip with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "render/field_dump.h"
#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

// The reason there is no GPU context, or "" when there is one.
std::string gpuUnavailable() {
  CommandResult r = runMorphoflow("info");
  const size_t at = r.output.find("gpu: unavailable: ");
  return at == std::string::npos ? "" : r.output.substr(at);
}

std::string explicitScene(const std::string& resolution, const std::string& size, const std::string& boundary) {
  return "name = \"gs\"\n[grid]\nresolution = " + resolution + "\n[domain]\nsize = " + size +
         "\n[time]\ndt = 0.5\nsteps = 200\n[rd]\nmodel = \"gray-scott\"\nintegrator = \"explicit\"\nboundary = \"" +
         boundary +
         "\"\ndiffusion = [2e-5, 1e-5]\n[rd.parameters]\nF = 0.035\nk = 0.062\n[rd.initial]\nvalues = [1.0, 0.0]\n"
         "square = 0.1\nsquare_values = [0.5, 0.25]\nnoise = [0.01, 0.01]\n[output]\nevery = 100\nfield = \"v\"\n"
         "fields = true\nimage_size = 64\n";
}

morphoflow::FieldDump dump(const fs::path& p) {
  morphoflow::FieldDump d;
  std::string error;
  EXPECT_TRUE(morphoflow::readFieldDump(p.string(), &d, &error)) << error;
  return d;
}

}  // namespace

TEST(Gpu, InfoNamesTheBackendsAndTheRendererOrWhyThereIsNone) {
  CommandResult r = runMorphoflow("info");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("backends: serial, tbb, gpu"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("gpu: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" threads; vector kernels "), std::string::npos) << r.output;
}

// With no EGL vendor library (libglvnd pointed at none), `info` says the GPU
// is unavailable and why, and a run that asks for it is exit 2 saying so:
// never an abort.
TEST(Gpu, WithoutAnEglVendorTheGpuIsUnavailableNotACrash) {
  setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/vendor.json", 1);
  const CommandResult info = runMorphoflow("info");
  const fs::path dir = tempDir("gpu_no_vendor");
  const CommandResult run = runMorphoflow(
      "run " + sceneFile("rd/gray_scott_pearson.toml") +
      " --set grid.resolution=[16,16] --set time.steps=2 --backend gpu --quiet --out " + (dir / "out").string());
  unsetenv("__EGL_VENDOR_LIBRARY_FILENAMES");
  EXPECT_EQ(info.status, 0) << info.output;
  EXPECT_NE(info.output.find("gpu: unavailable: "), std::string::npos) << info.output;
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("no usable GPU context"), std::string::npos) << run.output;
  fs::remove_all(dir);
}

// Explicit Gray-Scott: float on the GPU, double on the CPU; after 200 steps
// both species agree to 1e-5 everywhere (docs/gpu.md), and the pattern has
// moved far beyond that from its start.
TEST(Gpu, ExplicitGrayScottMatchesTheCpuIn2DAnd3D) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_parity");
  for (const auto& [res, size, boundary] : {std::tuple{"[64, 64]", "[0.5, 0.5]", "periodic"},
                                            std::tuple{"[48, 40]", "[0.375, 0.3125]", "neumann"},
                                            std::tuple{"[24, 24, 16]", "[0.1875, 0.1875, 0.125]", "periodic"}}) {
    const fs::path scene = dir / "gs.toml";
    std::ofstream(scene) << explicitScene(res, size, boundary);
    for (const char* backend : {"gpu", "tbb"}) {
      CommandResult r = runMorphoflow("run " + scene.string() + " --quiet --backend " + backend + " --out " +
                                      (dir / backend).string());
      ASSERT_EQ(r.status, 0) << res << " " << backend << "\n" << r.output;
    }
    const morphoflow::FieldDump g = dump(dir / "gpu" / "fields" / "000002.exr"),
                                c = dump(dir / "tbb" / "fields" / "000002.exr");
    const morphoflow::FieldDump start = dump(dir / "tbb" / "fields" / "000000.exr");
    ASSERT_EQ(g.resolution, c.resolution);
    ASSERT_EQ(g.channels.size(), 2u);
    EXPECT_EQ(g.step, 200);
    for (size_t s = 0; s < 2; ++s) {
      double worst = 0, moved = 0;
      for (size_t i = 0; i < c.channels[s].size(); ++i) {
        worst = std::max(worst, double(std::abs(g.channels[s][i] - c.channels[s][i])));
        moved = std::max(moved, double(std::abs(c.channels[s][i] - start.channels[s][i])));
      }
      EXPECT_LT(worst, 1e-5) << res << " species " << s;
      EXPECT_GT(moved, 1e-2) << res << " species " << s;
    }
    std::ifstream in(dir / "gpu" / "run.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["backend"], "gpu");
    EXPECT_FALSE(j["gl_renderer"].get<std::string>().empty());
    EXPECT_FALSE(j["gl_version"].get<std::string>().empty());
  }
  fs::remove_all(dir);
}

TEST(Gpu, AStageWithNoGpuProgramIsRefusedNamingIt) {
  const fs::path dir = tempDir("gpu_refused");
  const fs::path scene = dir / "gs.toml";
  std::ofstream(scene) << explicitScene("[32, 32]", "[0.25, 0.25]", "periodic");
  const std::string out = " --out " + (dir / "o").string();
  for (const auto& [args, stage] :
       {std::pair{sceneFile("coupled/cavity_gray_scott.toml") + " --set 'rd.lookup_table=true'",
                  std::string("the reaction lookup table")},
        std::pair{sceneFile("coupled/cavity_gray_scott.toml") +
                      " --set 'rd.model=\"brusselator-coupled\"' --set 'rd.diffusion=[1,1,1,1]' --set "
                      "'rd.parameters={}' --set 'rd.initial={}' --set 'output.field=\"a1\"'",
                  std::string("the chemicals' advection for a model of 4 species")}}) {
    CommandResult r = runMorphoflow("run " + args + " --backend gpu --quiet" + out);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find("the gpu backend has no program yet for " + stage), std::string::npos) << args << "\n"
                                                                                                   << r.output;
    EXPECT_FALSE(fs::exists(dir / "o" / "frames")) << args;  // refused before anything ran
  }
  fs::remove_all(dir);
}


namespace {

// The largest difference of a field dump's channel between the backends, and the channel's largest magnitude.
std::pair<double, double> channelDifference(const morphoflow::FieldDump& g, const morphoflow::FieldDump& c,
                                            const std::string& name) {
  double worst = 0, size = 0;
  for (size_t k = 0; k < c.names.size(); ++k) {
    if (c.names[k] != name) continue;
    for (size_t i = 0; i < c.channels[k].size(); ++i) {
      worst = std::max(worst, double(std::abs(g.channels[k][i] - c.channels[k][i])));
      size = std::max(size, double(std::abs(c.channels[k][i])));
    }
    return {worst, size};
  }
  ADD_FAILURE() << "no channel " << name;
  return {0, 0};
}

// How closely the backends must agree: every channel of the compared dump
// within relative x its largest value plus absolute; with `moved`, the CPU's
// channel changed since frame 0 by more than 1e-3 of its size (the check
// means something).
struct Parity {
  double relative = 0.0, absolute = 0.0;
  bool moved = false;
};

// The GPU's runs in each precision (gpu.precision): the parity tests run
// the GPU in double, as the CPU computes, and in float, the default.
const std::string kInDouble = " --set 'gpu.precision=\"double\"'";
const std::string kInFloat = " --set 'gpu.precision=\"float\"'";

// The worst difference of every channel of dump `g` from `c`, relative to the channel's largest magnitude.
double worstRelative(const morphoflow::FieldDump& g, const morphoflow::FieldDump& c) {
  double worst = 0;
  for (const std::string& channel : c.names) {
    const auto [w, size] = channelDifference(g, c, channel);
    worst = std::max(worst, size > 0 ? w / size : w);
  }
  return worst;
}

// Runs each scene (a scene file and its --set options, output.fields added)
// on the gpu backend in double and on tbb, and compares their dumps `frame`
// with `parity`; with `inFloat`, the gpu in float too, compared with it
// (the measured worst relative difference printed for docs/gpu.md).
void expectScenesAgree(const std::string& folder, const std::vector<std::string>& scenes, const std::string& frame,
                       Parity parity, const std::function<void(const fs::path&)>& checkRun = {},
                       std::optional<Parity> inFloat = std::nullopt) {
  const fs::path dir = tempDir(folder);
  for (const std::string& scene : scenes) {
    std::vector<std::pair<std::string, std::string>> runs = {{"gpu", "gpu" + kInDouble}, {"tbb", "tbb"}};
    if (inFloat) runs.push_back({"gpu_float", "gpu" + kInFloat});
    for (const auto& [name, backend] : runs) {
      CommandResult r = runMorphoflow("run " + scene + " --set output.fields=true --quiet --backend " + backend +
                                      " --out " + (dir / name).string());
      ASSERT_EQ(r.status, 0) << scene << " " << backend << "\n" << r.output;
      if (checkRun) checkRun(dir / name);
    }
    const morphoflow::FieldDump c = dump(dir / "tbb" / "fields" / frame);
    const morphoflow::FieldDump start = dump(dir / "tbb" / "fields" / "000000.exr");
    for (const auto& [name, backend] : runs) {
      if (name == "tbb") continue;
      const Parity& p = name == "gpu" ? parity : *inFloat;
      const morphoflow::FieldDump g = dump(dir / name / "fields" / frame);
      ASSERT_EQ(g.names, c.names) << scene;
      ASSERT_EQ(g.step, c.step) << scene;
      for (const std::string& channel : c.names) {
        const auto [worst, size] = channelDifference(g, c, channel);
        EXPECT_LE(worst, p.relative * size + p.absolute) << scene << " " << channel << " " << name;
        if (p.moved) {
          EXPECT_GT(channelDifference(c, start, channel).first, 1e-3 * size) << scene << " " << channel;
        }
      }
      if (name == "gpu_float") std::cout << "float parity: " << worstRelative(g, c) << " " << scene << "\n";
    }
    fs::remove_all(dir);
  }
}

}  // namespace

// The shipped fluid scenes, smaller and shorter, on both backends: speed,
// pressure and vorticity agree to the tolerances docs/gpu.md states (the
// solvers stop at 1e-6 each, and the MacCormack limiter amplifies the
// difference where it switches on one backend only), the gpu in double and
// in float (its solves at the float floor, 4e-6: measured 1.5e-5 to 4.2e-4,
// 3e-3 past the sub-cell obstacle, whose cut faces the float rounding of
// the velocity moves most). The centreline profiles agree to their printed digits.
TEST(Gpu, ShippedFluidScenesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_fluid_scenes");
  struct Case {
    std::string scene, sets;
    double tolerance, inFloat;  // relative to the field's largest magnitude, the gpu in double and in float
  };
  for (const Case& c :
       {Case{"lid_driven_cavity.toml", "--set grid.resolution=[48,48] --set time.duration=1.0", 2e-4, 1e-3},
        Case{"flow_past_obstacle.toml", "--set grid.resolution=[220,41] --set time.duration=0.2", 2e-4, 5e-4},
        // an obstacle smaller than a cell, cut and voxel (measured 2.3e-4 and 1.7e-4 in pressure)
        Case{"flow_past_obstacle.toml",
             "--set grid.resolution=[220,41] --set time.duration=0.2"
             " --set 'obstacles=[{center=[0.2,0.205],radius=0.004}]'",
             5e-4, 1e-2},
        Case{"flow_past_obstacle.toml",
             "--set grid.resolution=[220,41] --set time.duration=0.2"
             " --set 'obstacles=[{center=[0.2,0.2],radius=0.004,boundary=\"voxel\"}]'",
             5e-4, 1e-2},
        Case{"lid_driven_cavity_3d.toml", "--set grid.resolution=[16,16,16] --set time.duration=0.4", 5e-4, 1e-4},
        Case{"flow_past_obstacle_3d.toml", "--set grid.resolution=[24,8,8] --set time.duration=0.6", 5e-4, 1e-4}}) {
    for (const auto& [name, backend] : std::vector<std::pair<std::string, std::string>>{
             {"gpu", "gpu" + kInDouble}, {"gpu_float", "gpu" + kInFloat}, {"tbb", "tbb"}}) {
      CommandResult r = runMorphoflow("run " + sceneFile(c.scene) + " " + c.sets +
                                      " --set output.fields=true --set output.every=10"
                                      " --quiet --backend " +
                                      backend + " --out " + (dir / name).string());
      ASSERT_EQ(r.status, 0) << c.scene << " " << backend << "\n" << r.output;
    }
    fs::path last;
    for (const auto& e : fs::directory_iterator(dir / "tbb" / "fields")) last = std::max(last, e.path().filename());
    const morphoflow::FieldDump cpu = dump(dir / "tbb" / "fields" / last);
    EXPECT_GE(cpu.step, 20) << c.scene;
    for (const char* name : {"gpu", "gpu_float"}) {
      const bool single = std::string(name) == "gpu_float";
      const morphoflow::FieldDump g = dump(dir / name / "fields" / last);
      EXPECT_EQ(g.step, cpu.step) << c.scene;
      double measured = 0;
      for (const char* field : {"speed", "pressure", "vorticity"}) {
        const auto [worst, size] = channelDifference(g, cpu, field);
        EXPECT_GT(size, 0.0) << c.scene << " " << field;
        EXPECT_LE(worst, (single ? c.inFloat : c.tolerance) * size) << c.scene << " " << field << " " << name;
        measured = std::max(measured, worst / size);
      }
      if (single) std::cout << "float parity: " << measured << " " << c.scene << " " << c.sets << "\n";
      // the solves meet the tolerance they were given (float: raised to its floor, in run.json)
      std::ifstream in(dir / name / "run.json");
      const nlohmann::json j = nlohmann::json::parse(in);
      const double tolerance = j["gpu"]["tolerances"]["pressure"];
      EXPECT_EQ(tolerance, single ? 4e-6 : 1e-6) << c.scene;
      EXPECT_EQ(j["solvers"]["pressure_unconverged_steps"], 0) << c.scene << " " << name;
      EXPECT_LE(j["solvers"]["pressure_residual_max"].get<double>(), 1.0001 * tolerance) << c.scene << " " << name;
    }
    fs::remove_all(dir);
  }
}

namespace {

// Runs `args` + --out through once, then again killed (SIGKILL) after its
// first complete checkpoint and resumed (run.json says from where); every
// file under `subs` of the two output folders must be the same, byte for
// byte. Returns how many were compared.
int resumedRunMatches(const fs::path& dir, const std::vector<std::string>& args, const std::vector<std::string>& subs) {
  auto with = [&](const fs::path& out, std::vector<std::string> more = {}) {
    std::vector<std::string> a = args;
    a.push_back("--out");
    a.push_back(out.string());
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  EXPECT_EQ(waitMorphoflow(startMorphoflow(with(dir / "whole"), dir / "whole.log")), 0);
  const pid_t pid = startMorphoflow(with(dir / "cut"), dir / "cut.log");
  EXPECT_TRUE(waitUntil([&] {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir / "cut" / "checkpoints", ec))
      if (e.path().extension() == ".ckpt") return true;
    return false;
  }, 60));
  if (pid > 0) kill(pid, SIGKILL);
  waitMorphoflow(pid);
  EXPECT_EQ(waitMorphoflow(startMorphoflow(with(dir / "cut", {"--resume"}), dir / "resume.log")), 0);
  std::ifstream record(dir / "cut" / "run.json");
  const nlohmann::json j = nlohmann::json::parse(record);
  EXPECT_TRUE(j.contains("resumed_from")) << j.dump();
  int compared = 0;
  for (const std::string& sub : subs)
    for (const auto& e : fs::directory_iterator(dir / "whole" / sub)) {
      std::ifstream a(e.path(), std::ios::binary), b(dir / "cut" / sub / e.path().filename(), std::ios::binary);
      const std::string x(std::istreambuf_iterator<char>(a), {}), y(std::istreambuf_iterator<char>(b), {});
      EXPECT_EQ(x, y) << sub << "/" << e.path().filename();
      ++compared;
    }
  return compared;
}

}  // namespace

// A GPU fluid run killed after a checkpoint and resumed writes the same
// frames, field dumps and centreline profiles, bit for bit, as one that ran through.
TEST(Gpu, AKilledFluidRunResumesBitForBit) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_fluid_resume");
  EXPECT_GE(resumedRunMatches(dir, {"run", sceneFile("lid_driven_cavity.toml"), "--set", "grid.resolution=[32,32]",
                                    "--set", "time.duration=4.0", "--set", "output.every=20", "--set",
                                    "output.fields=true", "--set", "output.checkpoint_every=1", "--backend", "gpu",
                                    "--quiet"},
                              {"fields", "frames", "profiles"}),
            10);
  fs::remove_all(dir);
}

// The same for a coupled scene: the fluid, the species and the diffusion
// solves' warm starts all come back from the checkpoint.
TEST(Gpu, AKilledCoupledRunResumesBitForBit) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_coupled_resume");
  EXPECT_GE(resumedRunMatches(dir,
                              {"run", sceneFile("coupled/cavity_gray_scott.toml"), "--set", "grid.resolution=[32,32]",
                               "--set", "rd.resolution=[64,64]", "--set", "time.steps=240", "--set", "output.every=20",
                               "--set", "output.fields=true", "--set", "output.video=false", "--set",
                               "output.checkpoint_every=1", "--backend", "gpu", "--quiet"},
                              {"fields", "frames"}),
            20);
  fs::remove_all(dir);
}

// Moving obstacles: the GPU places them again where a resumed run's clock
// says, and its fill, systems and warm starts continue bit for bit (the
// towed cylinder; the paddle stirring Gray-Scott, whose chemicals follow it).
TEST(Gpu, AKilledRunWithMovingObstaclesResumesBitForBit) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_moving_resume");
  EXPECT_GE(
      resumedRunMatches(dir / "towed",
                        {"run", sceneFile("flow/towed_cylinder.toml"), "--set", "grid.resolution=[80,20]", "--set",
                         "time.duration=0.6", "--set", "output.every=20", "--set", "output.fields=true", "--set",
                         "output.video=false", "--set", "output.checkpoint_every=1", "--backend", "gpu", "--quiet"},
                        {"fields", "frames"}),
      5);
  EXPECT_GE(resumedRunMatches(dir / "paddle",
                              {"run", sceneFile("vfx/paddle_gray_scott.toml"), "--set", "grid.resolution=[32,32]",
                               "--set", "rd.resolution=[64,64]", "--set", "time.steps=120", "--set", "output.every=20",
                               "--set", "output.fields=true", "--set", "output.video=false", "--set",
                               "output.checkpoint_every=1", "--backend", "gpu", "--quiet"},
                              {"fields", "frames"}),
            5);
  fs::remove_all(dir);
}

// The measure of the coupled backend: scenes/coupled/cavity_gray_scott.toml
// as shipped (fluid 128^2, chemicals 256^2, Kim & Lin), 100 steps on each
// backend: every species within 1e-3 of the CPU's everywhere (measured 2.1e-5).
TEST(Gpu, CoupledCavityGrayScottMatchesTheCpuAfter100Steps) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  expectScenesAgree("gpu_cavity_gs",
                    {sceneFile("coupled/cavity_gray_scott.toml") +
                     " --set time.steps=100 --set output.every=50 --set output.video=false"},
                    "000002.exr", {0.0, 1e-3, true});
}

// Every other shipped coupled scene, smaller and shorter (the same ratio of
// the chemicals' grid to the fluid's): every species within 1e-4 of the
// CPU's (measured at most 2.1e-5), in float within 1e-2 (measured at most
// 3.2e-3, the BFECC channel), through each coupling mode (ard,
// passive, rd-only), linear, cubic, B-spline and BFECC transport, inflow
// and solid values, 2D and 3D.
TEST(Gpu, ShippedCoupledScenesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const std::string cavity =
      " --set grid.resolution=[32,32] --set rd.resolution=[64,64] --set time.steps=40 --set output.every=20";
  const std::string channel =
      " --set grid.resolution=[32,64] --set rd.resolution=[48,96] --set time.steps=40 --set output.every=20";
  auto scene = [](const char* name, const std::string& sets) {
    return sceneFile(std::string("coupled/") + name) + sets + " --set output.video=false";
  };
  expectScenesAgree("gpu_coupled_scenes",
                    {scene("cavity_barkley.toml", cavity), scene("cavity_fitzhugh_nagumo.toml", cavity),
                     scene("cavity_passive.toml", cavity), scene("obstacle_gray_scott_ard.toml", channel),
                     scene("obstacle_gray_scott_rd_only.toml", channel), scene("obstacle_passive.toml", channel),
                     scene("cavity_gray_scott_3d.toml",
                           " --set grid.resolution=[12,12,12] --set rd.resolution=[24,24,24]"
                           " --set time.steps=10 --set output.every=5 --set output.vdb=false"),
                     // the B-spline transport: walls, inflow and solids, 3D
                     scene("cavity_gray_scott.toml", cavity + " --set 'coupling.interpolation=\"bspline\"'"),
                     scene("obstacle_gray_scott_ard.toml", channel + " --set 'coupling.interpolation=\"bspline\"'"),
                     scene("cavity_gray_scott_3d.toml",
                           " --set grid.resolution=[12,12,12] --set rd.resolution=[24,24,24]"
                           " --set time.steps=10 --set output.every=5 --set output.vdb=false"
                           " --set 'coupling.interpolation=\"bspline\"'"),
                     // BFECC: walls, inflow and solids, 3D
                     scene("cavity_gray_scott.toml", cavity + " --set 'coupling.interpolation=\"bfecc\"'"),
                     scene("obstacle_gray_scott_ard.toml", channel + " --set 'coupling.interpolation=\"bfecc\"'"),
                     scene("cavity_gray_scott_3d.toml",
                           " --set grid.resolution=[12,12,12] --set rd.resolution=[24,24,24]"
                           " --set time.steps=10 --set output.every=5 --set output.vdb=false"
                           " --set 'coupling.interpolation=\"bfecc\"'"),
                     scene("obstacle_gray_scott_3d.toml",
                           " --set grid.resolution=[16,32,16] --set rd.resolution=[16,32,16]"
                           " --set time.steps=10 --set output.every=5")},
                    "000002.exr", {0.0, 1e-4, false}, {}, Parity{0.0, 1e-2, false});
}

// Moving obstacles, the shipped scenes smaller and shorter: the towed
// cylinder, the paddle stirring Gray-Scott (the solid followed on the
// chemicals' grid, the cells it uncovers filled on the device) and the
// sphere crossing the patterned plume (smoke, temperature and species)
// agree with the CPU in every channel to 1e-5 of its largest value in
// double (measured at most 2.0e-6, the paddle's u), to 2e-3 in float
// (measured at most 6.0e-4, the paddle's; at the scenes' tolerance).
TEST(Gpu, ShippedMovingObstacleScenesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  expectScenesAgree(
      "gpu_moving",
      {sceneFile("flow/towed_cylinder.toml") +
           " --set grid.resolution=[160,40] --set time.duration=0.5 --set output.every=50 --set output.video=false",
       sceneFile("vfx/paddle_gray_scott.toml") +
           " --set grid.resolution=[32,32] --set rd.resolution=[64,64] --set time.steps=60 --set output.every=30"
           " --set output.video=false",
       sceneFile("vfx/sphere_through_plume_3d.toml") +
           " --set grid.resolution=[12,20,12] --set rd.resolution=[24,40,24] --set time.duration=0.2"
           " --set output.every=10 --set output.vdb=false --set output.video=false"
           " --set 'obstacles.0.motion=[\"0.3 + 0.7 * t\", \"0.8\", \"0.6\"]'"},
      "000002.exr", {1e-5, 0.0, false}, {}, Parity{2e-3, 0.0, false});
}

// A scene with a timeline (scenes/coupled/cavity_timeline.toml: a stroke at
// t = 2, a deposit at 3, an obstacle from 4 to 10, F stepping at 5, the lid
// at 12), smaller, at a longer step, its lid keyed by steps: the GPU is built
// again at the same steps as the CPU (5 times) and its species agree within
// 1e-2 at t = 13 (measured 3.6e-3; a missed event is 0.25 off), in float
// within 3e-2 (measured 1.4e-2), the run having moved them.
TEST(Gpu, ATimelineSceneChangesAtTheCpusSteps) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  expectScenesAgree(
      "gpu_timeline",
      {sceneFile("coupled/cavity_timeline.toml") +
       " --set grid.resolution=[32,32] --set rd.resolution=[64,64] --set time.dt=0.04 --set time.steps=325"
       " --set output.every=100 --set output.video=false"
       " --set 'fluid.lid_velocity={keys=[[8.0,1.0],[12.0,0.4]],interpolation=\"step\"}'"},
      "000003.exr", {0.0, 1e-2, true},
      [](const fs::path& run) {
        std::ifstream in(run / "run.json");
        EXPECT_EQ(nlohmann::json::parse(in)["timeline"]["rebuilds"], 5) << run;
      },
      Parity{0.0, 3e-2, false});
}

// The pattern on the smoke (coupling.smoke_mask, sources' chemicals) on both
// backends: the patterned plumes, smaller and shorter, 2D and 3D, every
// species within 1e-5 of the CPU's (measured 1.5e-6 in 2D, 1.2e-7 in 3D: the
// mask reads the same taps and no cell's smoke sits within rounding of the
// threshold); in float within 2e-3 (measured at most 7.7e-4).
TEST(Gpu, PatternedPlumesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  auto scene = [](const char* name, const std::string& sets) {
    return sceneFile(std::string("vfx/") + name) + sets + " --set output.video=false --set output.vdb=false";
  };
  expectScenesAgree("gpu_plumes",
                    {scene("plume_gray_scott_2d.toml",
                           " --set grid.resolution=[32,48] --set rd.resolution=[64,96]"
                           " --set time.duration=1.0 --set output.every=50"),
                     scene("plume_gray_scott_2d.toml",
                           " --set grid.resolution=[32,48] --set rd.resolution=[64,96]"
                           " --set time.duration=0.6 --set output.every=30"
                           " --set 'sources.0.motion=[\"0.5 + 0.2 * t\", \"0.15\"]'"),
                     scene("plume_gray_scott_3d.toml",
                           " --set grid.resolution=[12,20,12] --set rd.resolution=[24,40,24]"
                           " --set time.duration=0.4 --set output.every=20")},
                    "000002.exr", {0.0, 1e-5, true}, {}, Parity{0.0, 2e-3, false});
}

// time.until_steady on the GPU in double: the run stops at the CPU's step,
// its last measured change within 1e-4 of the CPU's (measured 4e-5 relative).
TEST(Gpu, UntilSteadyStopsAtTheCpusStep) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_until_steady");
  std::map<std::string, nlohmann::json> got;
  for (const char* backend : {"gpu", "tbb"}) {  // (the gpu in double: the step it stops at is exact)
    const CommandResult r =
        runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") +
                      " --set grid.resolution=[24,24] --set output.images=false --set time.until_steady=5e-3"
                      " --quiet" +
                      kInDouble + " --backend " + backend + " --out " + (dir / backend).string());
    ASSERT_EQ(r.status, 0) << backend << "\n" << r.output;
    got[backend] = nlohmann::json::parse(std::ifstream(dir / backend / "run.json"))["until_steady"];
  }
  EXPECT_TRUE(got["gpu"]["steady"].get<bool>());
  EXPECT_EQ(got["gpu"]["steady_at"], got["tbb"]["steady_at"]);
  const double g = got["gpu"]["relative_change_per_time"], c = got["tbb"]["relative_change_per_time"];
  EXPECT_NEAR(g, c, 1e-4 * c);
  fs::remove_all(dir);
}

// The dispatches and host waits a step that run.json reports for the shipped
// coupled cavity (fluid 128^2, chemicals 256^2, 20 steps, no frame after the
// first): some of each (the speed's reduction for the CFL step and the
// finiteness check wait every step), and the stages' counts add up to the
// step's. Their budget is a benchmark's (`bench coupling --backend gpu`,
// app/dispatch_budget.h), not this test's.
TEST(Gpu, TheCoupledCavityStepsDispatchesAndHostWaitsAddUpOverItsStages) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_counts");
  const CommandResult r = runMorphoflow("run " + sceneFile("coupled/cavity_gray_scott.toml") +
                                        " --set time.steps=20 --set output.every=1000 --set output.video=false --quiet"
                                        " --backend gpu --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json g = nlohmann::json::parse(std::ifstream(dir / "run.json"))["gpu"];
  const double dispatches = g["dispatches_per_step"], waits = g["host_waits_per_step"];
  EXPECT_GT(dispatches, 0.0);
  EXPECT_GT(waits, 0.0);
  double sumD = 0, sumW = 0;
  for (const char* stage : {"forces", "advect", "diffuse", "project", "reaction-diffusion", "advect chemicals"}) {
    ASSERT_TRUE(g["stages"].contains(stage)) << stage;
    sumD += g["stages"][stage]["dispatches_per_step"].get<double>();
    sumW += g["stages"][stage]["host_waits_per_step"].get<double>();
  }
  EXPECT_NEAR(sumD, dispatches, 1e-9);
  EXPECT_NEAR(sumW, waits, 1e-9);
  fs::remove_all(dir);
}

// The shipped reaction-diffusion scenes with implicit integrators (Kim &
// Lin), at 96^2 for 100 steps, on both backends with the diffusion solves
// converged to 1e-12 (at the scenes' 1e-8 each backend's solve leaves its own
// error, which a forming pattern amplifies as it would a change of
// tolerance on the CPU alone): every species within 2e-4 of its largest value
// (measured at most 7e-5, Barkley's B beside a front; most agree to 1e-8).
// In float (the solves at its floor, 4e-6, and Newton at float's tolerance)
// within 1e-1 (measured 3.2e-4 for Gray-Scott and FitzHugh-Nagumo; 1.5e-2
// and 3.7e-2 for Turing's and Barkley's moving fronts, which a difference
// of a cell's fraction in a front's place makes).
TEST(Gpu, ShippedImplicitRDScenesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  std::vector<std::string> scenes;
  for (const char* s : {"rd/gray_scott_pearson.toml", "rd/turing_lawlor.toml", "rd/seeds/barkley_spiral.toml",
                        "rd/seeds/fitzhugh_nagumo_spiral.toml"})
    scenes.push_back(
        sceneFile(s) +
        " --set grid.resolution=[96,96] --set rd.tolerance=1e-12 --set time.steps=100 --set output.every=50");
  expectScenesAgree("gpu_rd_scenes", scenes, "000002.exr", {2e-4, 0.0, true}, {}, Parity{1e-1, 0.0, false});
}

// The GPU suites print the CPU suites' tables for the same problems (here at
// 32^2, on llvmpipe) and their JSON: every case converged, a positive rate,
// the modelled traffic over the time as GB/s and as a fraction of the
// device's measured copy bandwidth, the ARD part of a coupled step timed,
// the precision the suite ran in (float by default; no figure is asserted:
// timings on a shared machine are not tests).
TEST(Gpu, BenchSuitesTimeTheFluidTheLayerAndTheCoupling) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_bench");
  for (const char* suite : {"rd", "fluid", "coupling"}) {
    const fs::path json = dir / (std::string(suite) + ".json");
    CommandResult r =
        runMorphoflow(std::string("bench ") + suite + " --backend gpu --size 32 --seconds 0 --json " + json.string());
    ASSERT_EQ(r.status, 0) << suite << "\n" << r.output;
    EXPECT_NE(r.output.find("gpu: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("copy bandwidth: "), std::string::npos) << r.output;
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_FALSE(j.empty()) << suite;
    for (const nlohmann::json& c : j) {
      if (c.value("case", "") == "dispatch budget") {  // (coupling's last row: counts, not times)
        EXPECT_GT(c["dispatches_per_step"].get<double>(), 0.0) << c;
        EXPECT_GT(c["host_waits_per_step"].get<double>(), 0.0) << c;
        EXPECT_EQ(c["within_budget"].get<bool>(), c["dispatches_per_step"].get<double>() <= c["dispatch_budget"] &&
                                                      c["host_waits_per_step"].get<double>() <= c["host_wait_budget"])
            << c;
        continue;
      }
      EXPECT_GT(c.contains("ms") ? c["ms"].get<double>() : c["ms_per_step_median"].get<double>(), 0.0) << c;
      EXPECT_GT(c["gb_per_second"].get<double>(), 0.0) << c;
      EXPECT_GT(c["fraction_of_copy_bandwidth"].get<double>(), 0.0) << c;
      if (c.contains("precision")) {
        EXPECT_EQ(c["precision"], "float") << c;
      }
      if (c.contains("pressure_converged")) {
        EXPECT_TRUE(c["pressure_converged"].get<bool>()) << c;
      }
      if (c.contains("ard_part_ms")) {
        EXPECT_GT(c["ard_part_ms"].get<double>(), 0.0) << c;
      }
    }
    if (std::string(suite) == "rd") {
      EXPECT_EQ(j.size(), 2u) << "the explicit and the Kim & Lin rows";
    }
    if (std::string(suite) == "coupling") {
      EXPECT_EQ(j.back().value("case", ""), "dispatch budget") << "the budget's row, last";
      EXPECT_NE(r.output.find("dispatch budget (the shipped coupled cavity"), std::string::npos) << r.output;
    }
  }
  fs::remove_all(dir);
}

// Shipped scenes with parameter maps (an image, a Pearson F x k map), a fixed
// region, the four-species coupled Brusselator, fixed diffusion tensors (a
// saddle, circles, a four-species layer) and Kim & Lin's cosine lobes (three
// lobes, Witkin-Kass, a painted spiral steering one lobe), at 64^2 for 40 steps with
// the solves at 1e-12: every species within 1e-6 of its largest value
// (measured: float rounding of the dumps, or exactly equal); in float within
// 1e-3 (measured at most 4.6e-4, the Witkin-Kass lobes).
TEST(Gpu, ShippedMapFixedAndMultiSpeciesScenesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  std::vector<std::string> scenes;
  for (const char* s : {"lawlor_image_growth", "pearson_map", "sanderson_fig20", "sanderson_fig10", "sanderson_fig21",
                        "sanderson_fig06", "sanderson_fig07", "sanderson_fig18", "kim_lin_lobes3",
                        "kim_lin_witkin_kass", "kim_lin_paint_deposit", "kim_lin_paint_lobe"})
    scenes.push_back(
        sceneFile(std::string("rd/seeds/") + s + ".toml") +
        " --set grid.resolution=[64,64] --set rd.tolerance=1e-12 --set time.steps=40 --set output.every=20");
  expectScenesAgree("gpu_map_scenes", scenes, "000002.exr", {1e-6, 0.0, false}, {}, Parity{1e-3, 0.0, false});
}

// An explicit scene whose stroke deposits chemical: the cells under the
// stroke are held at the stroke's values on both backends (the GPU's explicit
// step is taken only where the CPU's fast path is: RDScene::plainExplicit),
// and the rest agrees within float rounding.
TEST(Gpu, ExplicitSceneWithDepositingStrokeHoldsItsCells) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_explicit_deposit");
  for (const char* backend : {"gpu", "tbb"}) {
    CommandResult r =
        runMorphoflow("run " + sceneFile("rd/seeds/kim_lin_paint_deposit.toml") +
                      " --set rd.integrator='\"explicit\"' --set grid.resolution=[64,64] --set time.steps=40"
                      " --set output.every=20 --set output.fields=true --quiet --backend " +
                      backend + " --out " + (dir / backend).string());
    ASSERT_EQ(r.status, 0) << backend << "\n" << r.output;
  }
  const morphoflow::FieldDump g = dump(dir / "gpu" / "fields" / "000002.exr"),
                              c = dump(dir / "tbb" / "fields" / "000002.exr");
  ASSERT_EQ(g.names, c.names);
  size_t held = 0;
  for (size_t i = 0; i < c.channels[0].size(); ++i) {
    if (c.channels[0][i] != 0.5f || c.channels[1][i] != 0.25f) continue;  // (the stroke's values, exact in float)
    ++held;
    EXPECT_EQ(g.channels[0][i], 0.5f) << "cell " << i;
    EXPECT_EQ(g.channels[1][i], 0.25f) << "cell " << i;
  }
  EXPECT_GT(held, 100u) << "the stroke covers cells";
  for (const std::string& species : c.names) {
    const auto [worst, size] = channelDifference(g, c, species);
    EXPECT_LE(worst, 1e-6 * size) << species;
  }
  fs::remove_all(dir);
}

// The coarse-to-fine start on the GPU in double (its 64^2 and 128^2 levels
// stepped by the double-precision layer: bitwise the CPU's start), then Turing's
// explicit step in single precision with b clamped at 0 after every step, as
// the CPU clamps it: within 1e-6 of the largest value after 20 steps
// (measured 1.4e-7).
TEST(Gpu, CoarseToFineStartAndClampedExplicitSpeciesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_coarse_to_fine");
  for (const char* backend : {"gpu", "tbb"}) {
    CommandResult r = runMorphoflow("run " + sceneFile("rd/turing_coarse_to_fine.toml") +
                                    " --set rd.coarse_to_fine.steps=100 --set time.steps=20 --set output.every=20"
                                    " --set output.fields=true --quiet" +
                                    kInDouble + " --backend " + backend + " --out " + (dir / backend).string());
    ASSERT_EQ(r.status, 0) << backend << "\n" << r.output;
  }
  for (const char* frame : {"000000.exr", "000001.exr"}) {
    const morphoflow::FieldDump g = dump(dir / "gpu" / "fields" / frame), c = dump(dir / "tbb" / "fields" / frame);
    for (const std::string& species : c.names) {
      const auto [worst, size] = channelDifference(g, c, species);
      if (std::string(frame) == "000000.exr")
        EXPECT_EQ(worst, 0.0) << species << ": the coarse levels' start";
      else
        EXPECT_LE(worst, 1e-6 * size) << species;
    }
  }
  std::ifstream in(dir / "gpu" / "run.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["coarse_to_fine"].size(), 2u) << j.dump();
  fs::remove_all(dir);
}

// gpu.precision: float by default; a Krylov tolerance the scene gives below
// float's floor is raised to it and said at the start, run.json holding the
// one used and the precision; "double" keeps it; any other precision is a
// located error, exit 2.
TEST(Gpu, AToleranceBelowFloatsFloorIsRaisedAndSaid) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_floor");
  const std::string scene = sceneFile("rd/gray_scott_pearson.toml") +
                            " --set grid.resolution=[32,32] --set time.steps=4 --set output.every=4";
  for (const std::string& precision : {std::string(), kInDouble}) {
    CommandResult r = runMorphoflow("run " + scene + " --set rd.tolerance=1e-12" + precision + " --backend gpu --out " +
                                    (dir / "o").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const bool single = precision.empty();
    EXPECT_EQ(
        r.output.find("warning: rd.tolerance = 1e-12 is below what the gpu's float solves reach: 4e-06 is used") !=
            std::string::npos,
        single)
        << r.output;
    std::ifstream in(dir / "o" / "run.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["gpu"]["precision"], single ? "float" : "double");
    EXPECT_EQ(j["gpu"]["tolerances"]["rd"].get<double>(), single ? 4e-6 : 1e-12);
  }
  // the default tolerance (1e-8) is raised too, unsaid
  CommandResult r = runMorphoflow("run " + scene + " --backend gpu --out " + (dir / "o").string());
  EXPECT_EQ(r.output.find("below what the gpu's float solves reach"), std::string::npos) << r.output;
  r = runMorphoflow("run " + scene + " --set 'gpu.precision=\"half\"' --out " + (dir / "half").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("'gpu.precision': 'half' is not one of: float, double"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "half" / "frames"));
  fs::remove_all(dir);
}

// The rest of the shipped seed scenes (Sanderson's figures 3, 4, 5a, 5b, 12
// and 15, the Turing spots, Lawlor's parameter map, Pearson's explicit
// theta), at 64^2 for 40 steps with the solves at 1e-12: every species
// within 1e-6 of its largest value (measured: equal, or float rounding); in
// float within 1e-3 (measured at most 3.6e-4).
TEST(Gpu, ShippedSeedScenesMatchTheCpu) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  std::vector<std::string> scenes = {
      sceneFile("rd/turing_spots_sanderson.toml") +
      " --set grid.resolution=[64,64] --set rd.tolerance=1e-12 --set time.steps=40 --set output.every=20"};
  for (const char* s : {"lawlor_parameter_map", "pearson_theta", "sanderson_fig03", "sanderson_fig04",
                        "sanderson_fig05a", "sanderson_fig05b", "sanderson_fig12", "sanderson_fig15"})
    scenes.push_back(
        sceneFile(std::string("rd/seeds/") + s + ".toml") +
        " --set grid.resolution=[64,64] --set rd.tolerance=1e-12 --set time.steps=40 --set output.every=20");
  expectScenesAgree("gpu_seed_scenes", scenes, "000002.exr", {1e-6, 0.0, false}, {}, Parity{1e-3, 0.0, false});
}

// A GPU reaction-diffusion run killed midway (SIGKILL) and resumed from its
// checkpoint writes the same fields, bit for bit, as one never stopped.
TEST(Gpu, AKilledRunResumesBitForBit) {
  if (const std::string why = gpuUnavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = tempDir("gpu_resume");
  const fs::path scene = dir / "gs.toml";
  std::string text = explicitScene("[64, 64]", "[0.5, 0.5]", "periodic");
  text.replace(text.find("steps = 200"), 11, "steps = 6000");
  text.replace(text.find("every = 100"), 11, "every = 500");
  std::ofstream(scene) << text + "checkpoint_every = 1\n";
  EXPECT_EQ(resumedRunMatches(dir, {"run", scene.string(), "--backend", "gpu", "--quiet"}, {"fields"}), 13);
  fs::remove_all(dir);
}
