// Patterns carried by a given velocity ([velocity], seed 004 sec. 3 and fig.
// 24): a chemical carried by a rigid rotation returns to its start, a
// constant field translates a blob by velocity x time, a VDB sequence written
// by a coupled run drives the same chemical fields as that run did, and the
// volume inputs that cannot serve are refused at once with their path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>

#include "render/field_dump.h"
#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

fs::path write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p;
}

morphoflow::FieldDump dump(const fs::path& file) {
  morphoflow::FieldDump d;
  std::string err;
  EXPECT_TRUE(morphoflow::readFieldDump(file.string(), &d, &err)) << file << ": " << err;
  return d;
}

// The centroid of channel c (cell centres, domain [0, size]^2), and its mass.
std::array<double, 3> centroid(const morphoflow::FieldDump& d, size_t c, double size) {
  const int nx = d.resolution[0], ny = d.resolution[1];
  double m = 0, mx = 0, my = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double v = d.channels[c][size_t(j * nx + i)];
      m += v, mx += v * (i + 0.5) * size / nx, my += v * (j + 0.5) * size / ny;
    }
  return {mx / m, my / m, m};
}

// A passive blob of v in a [velocity] scene.
std::string blobScene(const std::string& field, const std::string& boundary, double dt, int steps, int every,
                      const std::string& centre) {
  return "name = \"blob\"\n[grid]\nresolution = [64, 64]\n[domain]\nsize = [1.0, 1.0]\n[time]\ndt = " +
         std::to_string(dt) + "\nsteps = " + std::to_string(steps) + "\n[rd]\nmodel = \"gray-scott\"\nboundary = \"" +
         boundary + "\"\n[rd.initial]\nvalues = [1.0, 0.0]\n[rd.initial.maps]\nv = \"exp(-(" + centre +
         ") / 0.004)\"\n[velocity]\nfield = " + field +
         "\n[coupling]\nmode = \"passive\"\ninterpolation = \"cubic\"\n" +
         "[output]\nevery = " + std::to_string(every) + "\nfields = true\nimages = false\n";
}

}  // namespace

TEST(GivenVelocity, ARigidRotationReturnsTheChemicalToItsStart) {
  const fs::path dir = tempDir("rotation");
  const int steps = 200;
  const fs::path scene =
      write(dir / "rotation.toml", blobScene("[\"-(y - 0.5)\", \"x - 0.5\"]", "neumann", 2.0 * M_PI / steps, steps,
                                             steps / 2, "(x - 0.72)^2 + (y - 0.5)^2"));
  CommandResult r = runMorphoflow("run " + scene.string() + " --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const morphoflow::FieldDump d0 = dump(dir / "out" / "fields" / "000000.exr"),
                              dh = dump(dir / "out" / "fields" / "000001.exr"),
                              d1 = dump(dir / "out" / "fields" / "000002.exr");
  const double h = 1.0 / 64;
  const auto c0 = centroid(d0, 1, 1.0), ch = centroid(dh, 1, 1.0), c1 = centroid(d1, 1, 1.0);
  EXPECT_NEAR(ch[0], 1.0 - c0[0], 0.5 * h);  // half a turn: opposite the centre
  EXPECT_NEAR(ch[1], 1.0 - c0[1], 0.5 * h);
  EXPECT_NEAR(c1[0], c0[0], 0.5 * h);  // a whole turn: back where it started
  EXPECT_NEAR(c1[1], c0[1], 0.5 * h);
  double diff = 0, norm = 0, peak0 = 0, peak1 = 0;
  for (size_t i = 0; i < d0.channels[1].size(); ++i) {
    const double a = d0.channels[1][i], b = d1.channels[1][i];
    diff += (a - b) * (a - b), norm += a * a;
    peak0 = std::max(peak0, a), peak1 = std::max(peak1, b);
  }
  // What is lost is the cubic back-traces' smoothing over 200 steps (measured: 17% in L2, 21% of the peak).
  EXPECT_LT(std::sqrt(diff / norm), 0.25);
  EXPECT_GT(peak1, 0.7 * peak0);
  fs::remove_all(dir);
}

TEST(GivenVelocity, AConstantFieldTranslatesABlobByVelocityTimesTime) {
  const fs::path dir = tempDir("translation");
  // 0.25 along x and -0.125 along y for t = 1 on a periodic layer: (0.5, 0.5) -> (0.75, 0.375).
  const fs::path scene = write(dir / "translate.toml", blobScene("[\"0.25\", \"-0.125\"]", "periodic", 0.02, 50, 50,
                                                                  "(x - 0.5)^2 + (y - 0.5)^2"));
  CommandResult r = runMorphoflow("run " + scene.string() + " --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto c0 = centroid(dump(dir / "out" / "fields" / "000000.exr"), 1, 1.0);
  const auto c1 = centroid(dump(dir / "out" / "fields" / "000001.exr"), 1, 1.0);
  EXPECT_NEAR(c1[0] - c0[0], 0.25, 0.25 / 64);
  EXPECT_NEAR(c1[1] - c0[1], -0.125, 0.25 / 64);
  EXPECT_NEAR(c1[2], c0[2], 0.02 * c0[2]);  // a uniform translation keeps the mass
  fs::remove_all(dir);
}

namespace {

// A Gray-Scott layer on a 64^2 grid in a 32^2 lid-driven cavity: the coupled
// scene (`flow` a [fluid] table; the layer's own rd.resolution), or the same
// layer carried by a given [velocity] (the grid is then the layer's).
std::string cavityLayer(const std::string& flow) {
  const bool fluid = flow.find("[fluid]") != std::string::npos;
  return "name = \"cavity\"\nseed = 3\n[grid]\nresolution = " + std::string(fluid ? "[32, 32]" : "[64, 64]") +
         "\n[domain]\nsize = [1.0, 1.0]\n[time]\ndt = 0.01\nsteps = 12\n" + flow + "[rd]\nmodel = \"gray-scott\"\n" +
         (fluid ? "resolution = [64, 64]\n" : "") +
         "boundary = \"neumann\"\ndiffusion = [1.2e-5, 6e-6]\n"
         "[rd.initial]\nvalues = [1.0, 0.0]\nsquare = 0.4\nsquare_values = [0.5, 0.25]\nnoise = [0.02, 0.02]\n"
         "[coupling]\nrd_time_scale = 50.0\n[output]\nevery = 1\nfields = true\nimages = false\n";
}

}  // namespace

TEST(GivenVelocity, AVdbSequenceWrittenByACoupledRunDrivesTheSameChemicals) {
  const fs::path dir = tempDir("vdb_velocity");
  const fs::path coupled = write(dir / "coupled.toml", cavityLayer("[fluid]\nreynolds = 100\nlid_velocity = 1.0\n") +
                                                           "vdb = true\nvdb_mac_velocity = true\n");
  CommandResult r = runMorphoflow("run " + coupled.string() + " --quiet --out " + (dir / "coupled").string());
  ASSERT_EQ(r.status, 0) << r.output;
  ASSERT_TRUE(fs::exists(dir / "coupled" / "vdb" / "cavity.000012.vdb"));
  const fs::path given =
      write(dir / "given.toml", cavityLayer("[velocity]\nvdb = \"coupled/vdb/cavity.######.vdb\"\n"));
  r = runMorphoflow("run " + given.string() + " --quiet --out " + (dir / "given").string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* frame : {"000001.exr", "000012.exr"}) {
    const morphoflow::FieldDump a = dump(dir / "coupled" / "fields" / frame),
                                b = dump(dir / "given" / "fields" / frame);
    ASSERT_EQ(a.channels.size(), b.channels.size());
    for (size_t c = 0; c < a.channels.size(); ++c) {
      double worst = 0, peak = 0;
      for (size_t i = 0; i < a.channels[c].size(); ++i)
        worst = std::max(worst, double(std::abs(a.channels[c][i] - b.channels[c][i]))),
        peak = std::max(peak, double(a.channels[c][i]));
      EXPECT_LE(worst, 1e-6 * peak) << frame << " channel " << c;  // float rounding (measured: equal)
    }
  }
  // The flow visualisation's own volumes carry the velocity it read.
  const fs::path again =
      write(dir / "again.toml", cavityLayer("[velocity]\nvdb = \"coupled/vdb/cavity.######.vdb\"\n") + "vdb = true\n");
  r = runMorphoflow("run " + again.string() + " --set time.steps=2 --quiet --out " + (dir / "again").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "again" / "vdb" / "cavity.000002.vdb"));
  fs::remove_all(dir);
}

TEST(GivenVelocity, VolumesThatCannotServeAreRefusedWithTheirPath) {
  const fs::path dir = tempDir("vdb_bad");
  // A reaction-diffusion run's volumes hold species, no velocity.
  const std::string rd =
      "name = \"spots\"\n[grid]\nresolution = [16, 16]\n[time]\ndt = 1.0\nsteps = 2\n[rd]\nmodel = \"gray-scott\"\n"
      "[output]\nevery = 1\nimages = false\nvdb = true\n";
  CommandResult r =
      runMorphoflow("run " + write(dir / "spots.toml", rd).string() + " --quiet --out " + (dir / "spots").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path noVel = write(dir / "novel.toml",
                               "[grid]\nresolution = [16, 16]\n[rd]\nmodel = \"gray-scott\"\n[velocity]\n"
                               "vdb = \"spots/vdb/spots.######.vdb\"\n");
  r = runMorphoflow("validate " + noVel.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(noVel.string() + ":6:7"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no velocity grid 'vel'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("spots.000000.vdb"), std::string::npos) << r.output;
  // A cavity of size 1 does not fit a domain of size 2.
  const std::string cavity =
      "name = \"c\"\n[grid]\nresolution = [16, 16]\n[time]\ndt = 0.01\nsteps = 1\n[fluid]\nreynolds = 100\n"
      "[output]\nevery = 1\nimages = false\nvdb = true\n";
  r = runMorphoflow("run " + write(dir / "c.toml", cavity).string() + " --quiet --out " + (dir / "c").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path other = write(dir / "other.toml",
                               "[grid]\nresolution = [16, 16]\n[domain]\nsize = [2.0, 2.0]\n[rd]\n"
                               "model = \"gray-scott\"\n[velocity]\nvdb = \"c/vdb/c.######.vdb\"\n");
  r = runMorphoflow("validate " + other.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("domain of size"), std::string::npos) << r.output;
  // No file matches the pattern.
  const fs::path none =
      write(dir / "none.toml", "[rd]\nmodel = \"gray-scott\"\n[velocity]\nvdb = \"nothing/x.####.vdb\"\n");
  r = runMorphoflow("validate " + none.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("cannot list the folder"), std::string::npos) << r.output;
  // A frame number of 25 digits (a file there to match it) cannot be counted: exit 2, not an internal error.
  std::ofstream(dir / ("x." + std::string(25, '1') + ".vdb")) << "not a volume";
  const fs::path longer = write(
      dir / "long.toml", "[rd]\nmodel = \"gray-scott\"\n[velocity]\nvdb = \"x." + std::string(25, '#') + ".vdb\"\n");
  r = runMorphoflow("validate " + longer.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("25 '#' make a frame number too long to count"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// A velocity volume whose active voxels span a huge box (two voxels far
// apart: a file of a few KB) is refused by its size before it is read
// densely, for validate and run alike, and quickly. (Written with Debian's
// pyopenvdb, as a foreign tool would.)
TEST(GivenVelocity, AVolumeSpanningAHugeBoxIsRefusedBeforeItIsRead) {
  const fs::path dir = tempDir("vdb_huge");
  const std::string py = "import pyopenvdb as vdb\ng = vdb.Vec3SGrid()\ng.name = 'vel'\na = g.getAccessor()\n"
                         "a.setValueOn((0, 0, 0), (1, 0, 0))\na.setValueOn((4000, 4000, 4000), (1, 0, 0))\n"
                         "vdb.write('" + (dir / "far.0000.vdb").string() + "', grids=[g])\n";
  std::ofstream(dir / "write.py") << py;
  if (std::system(("/usr/bin/python3 " + (dir / "write.py").string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "no pyopenvdb";
  ASSERT_LT(fs::file_size(dir / "far.0000.vdb"), 100000u);
  const fs::path scene = write(dir / "far.toml",
                               "[grid]\nresolution = [16, 16]\n[rd]\nmodel = \"gray-scott\"\n[velocity]\n"
                               "vdb = \"far.####.vdb\"\nframe_time = 1.0\n");
  for (const std::string& cmd :
       {"validate " + scene.string(), "run " + scene.string() + " --quiet --out " + (dir / "o").string()}) {
    const CommandResult r = runMorphoflow(cmd);
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.output;
    EXPECT_NE(r.output.find("far.0000.vdb"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("Mi cells a velocity volume may span"), std::string::npos) << r.output;
  }
  fs::remove_all(dir);
}

// The shipped flow scenes run (briefly): the dipole's speed map and
// velocity-aligned tensor, and the shipped VDB sequence blended in time; the
// gpu backend refuses a given velocity at once.
TEST(GivenVelocity, ShippedFlowScenesRunAndTheGpuBackendRefusesThem) {
  const fs::path dir = tempDir("flow_scenes");
  for (const char* name : {"sanderson_fig24_dipole", "cavity_vdb_gray_scott"}) {
    const std::string file = sceneFile(std::string("flow/") + name + ".toml");
    CommandResult r =
        runMorphoflow("run " + file + " --set grid.resolution=[64,64] --set time.steps=50 --set output.every=50" +
                      " --set output.fields=true --quiet --out " + (dir / name).string());
    ASSERT_EQ(r.status, 0) << name << ": " << r.output;
    const morphoflow::FieldDump d = dump(dir / name / "fields" / "000001.exr");
    for (const std::vector<float>& c : d.channels)
      for (float v : c) ASSERT_TRUE(std::isfinite(v)) << name;
    nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / name / "run.json"));
    EXPECT_TRUE(j["resolved"].contains("velocity")) << name;
    r = runMorphoflow("run " + file + " --backend gpu --quiet --out " + (dir / "gpu").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("given [velocity]"), std::string::npos) << r.output;
  }
  // The speed map reaches the solver: a uniform s (an empty speed range) grows another pattern.
  CommandResult r =
      runMorphoflow("run " + sceneFile("flow/sanderson_fig24_dipole.toml") +
                    " --set grid.resolution=[64,64] --set time.steps=50 --set output.every=50 --set output.fields=true"
                    " --set velocity.speed_range=[0.0078125,0.0078125] --quiet --out " +
                    (dir / "uniform").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(dump(dir / "uniform" / "fields" / "000001.exr").channels,
            dump(dir / "sanderson_fig24_dipole" / "fields" / "000001.exr").channels);
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "uniform" / "run.json"));
  EXPECT_EQ(j["velocity_reference_speed"].get<double>(), 1.0);
  fs::remove_all(dir);
}
