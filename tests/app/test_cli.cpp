// The command line: bad scene files exit 2 with file:line:column, the key
// and a suggestion; overrides work; outputs are complete; no input crashes.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <regex>
#include <set>

#include <nlohmann/json.hpp>

#include "render/field_dump.h"
#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

fs::path writeScene(const fs::path& dir, const std::string& name, const std::string& text) {
  fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

const char* kSmall = R"(
[grid]
resolution = [16, 16]
[time]
dt = 0.01
steps = 4
[fluid]
viscosity = 0.01
lid_velocity = 1.0
[output]
images = false
)";

// A Gray-Scott layer of 32^2 unit cells from a perturbed square, 20 steps,
// a frame of v every 10 (further [output] keys may follow).
const char* const kGrayScottScene = R"(
[grid]
resolution = [32, 32]
[time]
dt = 1.0
steps = 20
[rd]
model = "gray-scott"
diffusion = [0.2, 0.1]
[rd.initial]
square = 0.25
square_values = [0.5, 0.25]
noise = 0.01
[output]
every = 10
field = "v"
)";

}  // namespace

struct BadScene {
  std::string name, text, expectLocation, expectWords;
};
void PrintTo(const BadScene& b, std::ostream* os) { *os << b.name; }

class BadScenes : public ::testing::TestWithParam<BadScene> {};

TEST_P(BadScenes, ExitTwoWithLocationAndHint) {
  auto dir = tempDir("bad");
  const BadScene& b = GetParam();
  fs::path p = writeScene(dir, b.name + ".toml", b.text);
  CommandResult r = runMorphoflow("validate " + p.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(p.string() + ":" + b.expectLocation), std::string::npos)
      << "expected location " << b.expectLocation << " in: " << r.output;
  EXPECT_NE(r.output.find(b.expectWords), std::string::npos) << r.output;
  // `run` reports the same error and writes nothing.
  CommandResult run = runMorphoflow("run " + p.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(run.status, 2);
  EXPECT_FALSE(fs::exists(dir / "out" / "run.json"));
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadScenes,
    ::testing::Values(
        BadScene{"unknown_key", "[fluid]\nviscosty = 0.1\n", "2:1", "did you mean 'fluid.viscosity'"},
        BadScene{"video_without_png", "[output]\nformat = \"exr\"\nvideo = true\n", "3:9",
                 "needs output.images = true"},
        BadScene{"video_fps", "[output]\nvideo = true\nfps = 0\n", "3:7", "output.fps"},
        BadScene{"unknown_table", "[fluids]\nviscosity = 0.1\n", "1:1", "did you mean 'fluid'"},
        BadScene{"wrong_type", "[grid]\nresolution = \"big\"\n", "2:14", "expected an array of numbers"},
        BadScene{"out_of_range", "[fluid]\npressure_tolerance = -1\n", "2:22", "expected a number in"},
        BadScene{"bad_choice", "[fluid]\nadvection = \"maccormak\"\n", "2:13", "did you mean 'maccormack'"},
        BadScene{"syntax", "[grid\nresolution = [1]\n", "1:", "not valid TOML"},
        BadScene{"wrong_length", "[grid]\nresolution = [8, 8, 8, 8]\n", "2:14", "2 or 3 numbers"},
        BadScene{"non_square", "[grid]\nresolution = [64, 32]\n[domain]\nsize = [1.0, 1.0]\n", "4:8",
                 "domain.size = [1, 0.5]"},
        BadScene{"both_re_and_nu", "[fluid]\nreynolds = 100\nviscosity = 0.01\n", "2:12", "not both"},
        BadScene{"inflow_no_outflow", "[boundary]\nx_min = \"inflow\"\n", "2:9", "needs an outflow"},
        BadScene{"vdb_unknown_field", "[output]\nvdb = true\nvdb_fields = [\"sped\"]\n", "3:15",
                 "did you mean 'speed'"},
        BadScene{"vdb_density_not_a_field", "[output]\nvdb = true\nvdb_density = \"u\"\n", "3:15", "is not one of"},
        BadScene{"vdb_fields_without_fluid",
                 "[rd]\nmodel = \"gray-scott\"\n[output]\nvdb = true\nvdb_fields = [\"speed\"]\n", "5:14",
                 "has no fluid"},
        BadScene{"unknown_view", "[output]\nview = \"volum\"\n", "2:8", "did you mean 'volume'"},
        BadScene{"pattern_contrast_without_smoke", "[output]\npattern_contrast = 0.5\n", "2:20", "no [smoke]"},
        BadScene{"emission_in_2d", "[output]\nemission = 2.0\n", "2:12", "no 3D [smoke]"},
        BadScene{"volume_view_in_2d", "[output]\nview = \"volume\"\n", "2:8", "for 3D scenes"},
        BadScene{"vdb_option_without_vdb", "[output]\nvdb_half = true\n", "2:12",
                 "only applies with output.vdb = true"},
        BadScene{"checkpoint_every_negative", "[output]\ncheckpoint_every = -1\n", "2:20", "output.checkpoint_every"},
        BadScene{"obstacle_outside", "[[obstacles]]\nshape = \"circle\"\ncenter = [2.0, 0.5]\nradius = 0.1\n", "3:10",
                 "outside the domain"},
        BadScene{"missing_radius", "[[obstacles]]\nshape = \"circle\"\n", "1:1", "needs a radius"},
        BadScene{
            "obstacle_motion_not_finite",
            "[time]\nsteps = 100\n[[obstacles]]\nradius = 0.1\nmotion = [\"0.5\", \"0.5 + 0.01 * log(t - 0.25)\"]\n",
            "5:10", "the motion is not finite at t = 0 "},
        BadScene{"obstacle_motion_too_fast",
                 "[time]\ndt = 0.01\nsteps = 10\n[[obstacles]]\nradius = 0.05\nmotion = [\"0.5\", \"0.5 + 10 * t\"]\n",
                 "6:10", "more than its half thickness 0.05"},
        BadScene{"obstacle_rotation_of_an_image",
                 "[[obstacles]]\nshape = \"image\"\nfile = \"nope.png\"\nrotation = [\"t\"]\n", "4:12",
                 "no centre to turn about"},
        BadScene{"obstacle_motion_of_an_sdf",
                 "[[obstacles]]\nshape = \"sdf\"\nfile = \"nope.png\"\nmotion = [\"t\", \"0\"]\n", "4:10",
                 "no centre to move"},
        BadScene{"obstacle_rotation_count", "[[obstacles]]\nradius = 0.1\nrotation = [\"t\", \"0\"]\n", "3:12",
                 "expected 1 expressions in t"},
        BadScene{"obstacle_motion_and_center",
                 "[[obstacles]]\nradius = 0.1\ncenter = [0.5, 0.5]\nmotion = [\"t\", \"0.5\"]\n", "3:10",
                 "the motion gives the centre"},
        BadScene{"obstacle_motion_syntax", "[[obstacles]]\nradius = 0.1\nmotion = [\"0.5 +\", \"0.5\"]\n",
                 "3:", "in the motion expression"},
        BadScene{"bad_palette", "[output]\ncolormap = \"virdis\"\n", "2:12", "did you mean 'viridis'"},
        BadScene{"missing_image", "[[obstacles]]\nshape = \"image\"\nfile = \"nope.png\"\n", "3:8", "cannot read"},
        BadScene{"image_obstacle_center",
                 "[[obstacles]]\nshape = \"image\"\ncenter = [0.5, 0.5]\nfile = \"nope.png\"\n", "3:10",
                 "a center does not apply"},
        BadScene{"rd_unknown_model", "[rd]\nmodel = \"grey-scott\"\n", "2:9", "did you mean 'gray-scott'"},
        BadScene{"rd_negative_diffusion", "[rd]\nmodel = \"gray-scott\"\ndiffusion = [1.0, -0.5]\n", "3:19",
                 "expected a number in [0,"},
        BadScene{"rd_unknown_parameter", "[rd]\nmodel = \"gray-scott\"\n[rd.parameters]\nf = 0.04\n", "4:5",
                 "did you mean 'rd.parameters.F'"},
        BadScene{"rd_bad_palette", "[rd]\nmodel = \"barkley\"\n[output]\ncolormap = \"jet\"\n", "4:12",
                 "is not one of"},
        BadScene{"rd_bad_species", "[rd]\nmodel = \"barkley\"\n[output]\nfield = \"u\"\n", "4:9", "A, B"},
        BadScene{"rd_missing_model", "[rd]\nintegrator = \"kim-lin\"\n", "1:1", "needs rd.model"},
        BadScene{"rd_map_syntax", "[rd]\nmodel = \"turing-sanderson\"\n[rd.maps]\nbeta = \"16 - 0.5 * r /\"\n", "4:23",
                 "expected a number, a name or '('"},
        BadScene{"rd_map_unknown_name", "[rd]\nmodel = \"turing-sanderson\"\n[rd.maps]\nbeta = \"16 + rr\"\n", "4:14",
                 "unknown name 'rr'"},
        BadScene{"rd_map_unknown_parameter", "[rd]\nmodel = \"turing-sanderson\"\n[rd.maps]\nbetta = \"16\"\n", "4:9",
                 "did you mean 'beta'"},
        BadScene{"rd_map_not_finite",
                 "[grid]\nresolution = [8, 8]\n[rd]\nmodel = \"turing-sanderson\"\n[rd.maps]\nbeta = \"1 / (i - 3)\"\n",
                 "6:8", "not finite at cell (3, 0)"},
        BadScene{"rd_map_missing_image",
                 "[rd]\nmodel = \"turing-sanderson\"\n[rd.maps]\nbeta = { image = \"nope.png\" }\n", "4:18",
                 "cannot read the image"},
        BadScene{"rd_initial_map_species", "[rd]\nmodel = \"barkley\"\n[rd.initial.maps]\nu = \"x\"\n", "4:5",
                 "not a species of barkley"},
        BadScene{"rd_fixed_empty", "[rd]\nmodel = \"brusselator\"\n[[rd.fixed]]\nwhere = \"j < 0\"\nvalues = [0, 5]\n",
                 "4:9", "no cell is inside"},
        BadScene{"rd_fixed_species",
                 "[rd]\nmodel = \"brusselator\"\n[[rd.fixed]]\nwhere = \"j == 0\"\nspecies = [\"c\"]\nvalues = [0]\n",
                 "5:12", "expected species names of brusselator: a, b"},
        BadScene{"rd_fixed_values", "[rd]\nmodel = \"brusselator\"\n[[rd.fixed]]\nwhere = \"j == 0\"\nvalues = [0]\n",
                 "5:10", "expected 2 numbers"},
        BadScene{"rd_anisotropy_negative",
                 "[grid]\nresolution = [8, 8]\n[rd]\nmodel = \"brusselator\"\n[rd.anisotropy]\nlambda2 = \"x - 0.5\"\n",
                 "6:11", "must be > 0"},
        BadScene{"rd_anisotropy_both",
                 "[rd]\nmodel = \"brusselator\"\n[rd.anisotropy]\ntheta = 0\ndirection = [\"x\", \"y\"]\n", "4:9",
                 "not both"},
        BadScene{"rd_anisotropy_direction", "[rd]\nmodel = \"brusselator\"\n[rd.anisotropy]\ndirection = [\"x\"]\n",
                 "4:13", "array of 2 fields"},
        BadScene{"rd_anisotropy_shape_species",
                 "[rd]\nmodel = \"brusselator\"\n[rd.anisotropy]\nshape = 0.2\nshape_species = \"c\"\n", "5:17",
                 "is not one of"},
        BadScene{"rd_lobes_missing_speeds", "[rd]\nmodel = \"gray-scott\"\n[rd.cosine_lobes]\ntheta0 = 0.5\n", "3:1",
                 "need speeds = [a_1, ..., a_j]"},
        BadScene{"rd_lobes_negative", "[rd]\nmodel = \"gray-scott\"\n[rd.cosine_lobes]\nspeeds = [1.0, -1.0]\n", "4:16",
                 "expected a number in [0,"},
        BadScene{"rd_lobes_all_zero", "[rd]\nmodel = \"gray-scott\"\n[rd.cosine_lobes]\nspeeds = [0, 0]\n", "4:10",
                 "give at least one lobe a positive speed"},
        BadScene{"rd_lobes_witkin_kass",
                 "[rd]\nmodel = \"gray-scott\"\n[rd.cosine_lobes]\nwitkin_kass = true\nspeeds = [1, 2, 3]\n", "5:10",
                 "expected 2 numbers"},
        BadScene{"rd_lobes_and_tensor",
                 "[rd]\nmodel = \"gray-scott\"\n[rd.anisotropy]\nlambda1 = 2\n[rd.cosine_lobes]\nspeeds = [1]\n", "5:1",
                 "use one"},
        BadScene{"rd_lobes_unknown_key", "[rd]\nmodel = \"gray-scott\"\n[rd.cosine_lobes]\nspeeds = [1]\ntheta_0 = 1\n",
                 "5:1", "did you mean 'rd.cosine_lobes.theta0'"},
        BadScene{"stroke_outside", "[rd]\nmodel = \"gray-scott\"\n[[rd.strokes]]\npoints = [[1, 1], [900, 1]]\n",
                 "4:19", "outside the domain"},
        BadScene{"stroke_one_point", "[rd]\nmodel = \"gray-scott\"\n[[rd.strokes]]\npoints = [[1, 1]]\n", "4:10",
                 "at least two points"},
        BadScene{"stroke_point_length", "[rd]\nmodel = \"gray-scott\"\n[[rd.strokes]]\npoints = [[1, 1], [2]]\n",
                 "4:19", "expected a point [x, y]"},
        BadScene{"stroke_deposit_without_values",
                 "[rd]\nmodel = \"gray-scott\"\n[[rd.strokes]]\npoints = [[1, 1], [2, 2]]\nspecies = [\"v\"]\n", "3:1",
                 "needs values"},
        BadScene{"strokes_theta0_without_strokes",
                 "[rd]\nmodel = \"gray-scott\"\n[rd.cosine_lobes]\nspeeds = [1]\ntheta0 = \"strokes\"\n", "5:10",
                 "but the scene has none"},
        BadScene{"stroke_image_missing", "[rd]\nmodel = \"gray-scott\"\n[[rd.strokes]]\nimage = \"dark.png\"\n", "4:9",
                 "cannot read"},
        BadScene{"normal_map_3d", "[grid]\nresolution = [8, 8, 8]\n[output]\nnormal_map = true\n", "4:14",
                 "this scene is 3D"},
        BadScene{"normal_strength_zero", "[output]\nnormal_map = true\nnormal_strength = 0\n", "3:19",
                 "output.normal_strength"},
        BadScene{"generalized_unknown_preset", "[rd]\nmodel = \"gray-scott\"\n[rd.generalized]\npreset = \"g\"\n",
                 "4:10", "is not one of"},
        BadScene{"generalized_wrong_rank", "[rd]\nmodel = \"gray-scott\"\n[rd.generalized]\nd3 = [1, 0, 0, 1, 0]\n",
                 "4:6", "rank-3 tensor: 4 unique components"},
        BadScene{"generalized_3d",
                 "[grid]\nresolution = [8, 8, 8]\n[rd]\nmodel = \"gray-scott\"\n[rd.generalized]\npreset = \"d\"\n",
                 "5:1", "this scene is 3D"},
        BadScene{"generalized_walls",
                 "[rd]\nmodel = \"gray-scott\"\nboundary = \"neumann\"\n[rd.generalized]\npreset = \"d\"\n", "4:1",
                 "needs a periodic layer"},
        BadScene{"generalized_unstable",
                 "[time]\ndt = 1.0\n[rd]\nmodel = \"gray-scott\"\nintegrator = \"explicit\"\ndiffusion = [0.2, "
                 "0.1]\n[rd.generalized]\npreset = \"d\"\n",
                 "7:1", "the largest step within the bound"},
        BadScene{"velocity_wrong_length", "[rd]\nmodel = \"gray-scott\"\n[velocity]\nfield = [\"1\"]\n", "4:9",
                 "expected two expressions"},
        BadScene{"velocity_unknown_variable", "[rd]\nmodel = \"gray-scott\"\n[velocity]\nfield = [\"1\", \"q\"]\n",
                 "4:16", "in the velocity expression"},
        BadScene{"velocity_with_fluid",
                 "[fluid]\nreynolds = 100\n[rd]\nmodel = \"gray-scott\"\n[velocity]\nfield = [\"1\", \"0\"]\n", "5:1",
                 "has a [fluid]"},
        BadScene{"velocity_both", "[rd]\nmodel = \"gray-scott\"\n[velocity]\nfield = [\"1\", \"0\"]\nvdb = \"a.vdb\"\n",
                 "5:7", "not both"},
        BadScene{"velocity_python_and_field",
                 "[rd]\nmodel = \"gray-scott\"\n[velocity]\npython = true\nfield = [\"1\", \"0\"]\n", "5:9",
                 "give no field or vdb"},
        BadScene{"speed_map_without_velocity", "[rd]\nmodel = \"turing-sanderson\"\n[rd.maps]\ns = \"speed\"\n", "4:5",
                 "has no [velocity]"},
        BadScene{"coupling_without_rd", "[fluid]\nreynolds = 100\n[coupling]\nmode = \"ard\"\n", "3:1",
                 "lacks one of them"},
        BadScene{"coupling_bad_mode",
                 "[fluid]\nreynolds = 100\n[rd]\nmodel = \"gray-scott\"\n[coupling]\nmode = \"pasive\"\n", "6:8",
                 "did you mean 'passive'"},
        BadScene{"coupling_boundary_mismatch",
                 "[fluid]\nreynolds = 100\n[rd]\nmodel = \"gray-scott\"\nboundary = \"periodic\"\n", "5:12",
                 "must wrap exactly where the fluid does"}),
    [](const ::testing::TestParamInfo<BadScene>& i) { return i.param.name; });

// A scene whose velocity comes from Python validates, but the command line
// cannot run it: exit 2 at the key, pointing to the module.
TEST(Cli, APythonVelocitySceneIsRefusedByRun) {
  auto dir = tempDir("python_velocity");
  fs::path p = writeScene(dir, "p.toml", "[rd]\nmodel = \"gray-scott\"\n[velocity]\npython = true\n");
  EXPECT_EQ(runMorphoflow("validate " + p.string()).status, 0);
  CommandResult run = runMorphoflow("run " + p.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find(p.string() + ":4:10"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("set_velocity"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir / "out" / "run.json"));
  fs::remove_all(dir);
}

TEST(Cli, MissingFileAndBadOverrideExitTwo) {
  CommandResult r = runMorphoflow("validate /nonexistent/scene.toml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("cannot open"), std::string::npos);
  auto dir = tempDir("override");
  fs::path p = writeScene(dir, "s.toml", kSmall);
  r = runMorphoflow("run " + p.string() + " --set fluid.viscosity=abc --out " + dir.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--set fluid.viscosity=abc"), std::string::npos) << r.output;
  r = runMorphoflow("run " + p.string() + " --set fluid.viscosityy=1 --out " + dir.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("did you mean 'fluid.viscosity'"), std::string::npos) << r.output;
  r = runMorphoflow("run " + p.string() + " --frames 5:2 --out " + dir.string());
  EXPECT_EQ(r.status, 2);
  fs::remove_all(dir);
}

// An error inside a --set value (an element of an array or a table given
// whole, an expression) points at the column of that element in the value.
TEST(Cli, AnOverrideErrorPointsAtTheElementWithinTheValue) {
  auto dir = tempDir("override_column");
  const std::string scene = writeScene(dir, "s.toml", kSmall).string();
  struct Case {
    std::string set, bad, key;
  };
  for (const Case& c :
       {Case{"obstacles=[{shape=\"circle\", center=[0.5, \"q\"], radius=0.1}]", "\"q\"", "obstacles.0.center"},
        Case{"obstacles=[{shape=\"circle\", center=[0.5, 0.5], radius=-1}]", "-1", "obstacles.0.radius"},
        Case{"fluid.viscosity=-1", "-1", "fluid.viscosity"},
        Case{"output.vdb_density=\"speed * nope\"", "nope", "output.vdb_density"}}) {
    const CommandResult r =
        runMorphoflow("run " + scene + " --quiet --out " + (dir / "o").string() + " --set '" + c.set + "'");
    EXPECT_EQ(r.status, 2) << r.output;
    const std::string at =
        "--set " + c.set + ":1:" + std::to_string(c.set.find(c.bad) + 1) + ": error: '" + c.key + "'";
    EXPECT_NE(r.output.find(at), std::string::npos) << "expected " << at << "\n" << r.output;
  }
  fs::remove_all(dir);
}

TEST(Cli, OverridesReachTheSimulationAndRunJsonIsComplete) {
  auto dir = tempDir("run");
  fs::path p = writeScene(dir, "s.toml", kSmall);
  CommandResult r = runMorphoflow("run " + p.string() +
                                  " --set grid.resolution=[24,24] --set fluid.reynolds=50 --set output.images=true"
                                  " --set output.every=2 --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "out" / "run.json"));
  EXPECT_EQ(j["resolved"]["resolution"], nlohmann::json({24, 24}));
  EXPECT_NEAR(j["resolved"]["viscosity"].get<double>(), 1.0 / 50.0, 1e-12);  // U L / Re
  EXPECT_EQ(j["steps"].get<int>(), 4);
  EXPECT_TRUE(j.contains("version"));
  for (const char* stage : {"forces", "advect", "diffuse", "project"}) EXPECT_TRUE(j["stages"].contains(stage));
  EXPECT_GT(j["solvers"]["pressure_iterations_mean"].get<double>(), 0.0);
  // Frames 0, 2 and 4 (every 2 steps, the initial state included).
  for (const char* f : {"000000.png", "000001.png", "000002.png"})
    EXPECT_TRUE(fs::exists(dir / "out" / "frames" / f)) << f;
  EXPECT_FALSE(fs::exists(dir / "out" / "frames" / "000003.png"));
  fs::remove_all(dir);
}

TEST(Cli, SerialAndTbbBackendsGiveIdenticalResults) {
  auto dir = tempDir("backends");
  fs::path p = writeScene(dir, "s.toml", kSmall);
  for (std::string b : {"serial", "tbb"}) {
    CommandResult r =
        runMorphoflow("run " + p.string() + " --set probes.centerlines=true --set time.steps=30 --backend " + b +
                      " --quiet --out " + (dir / b).string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  auto read = [](const fs::path& f) {
    std::ifstream in(f);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const char* f : {"u_vertical_centerline.csv", "v_horizontal_centerline.csv"})
    EXPECT_EQ(read(dir / "serial" / "profiles" / f), read(dir / "tbb" / "profiles" / f)) << f;
  fs::remove_all(dir);
}

TEST(Cli, ShippedScenesValidate) {
  for (const char* s : {"lid_driven_cavity.toml", "lid_driven_cavity_3d.toml", "flow_past_obstacle.toml",
                        "flow_past_obstacle_3d.toml"}) {
    CommandResult r = runMorphoflow("validate " + sceneFile(s));
    EXPECT_EQ(r.status, 0) << s << ": " << r.output;
  }
}

// Every shipped coupled scene validates, and runs at low resolution with
// both backends to the same float dumps of its species (the RD grid may differ
// from the fluid's).
TEST(Cli, CoupledScenesRunAndBackendsAgree) {
  auto dir = tempDir("coupled");
  for (const char* s :
       {"cavity_gray_scott.toml", "cavity_passive.toml", "cavity_barkley.toml", "cavity_fitzhugh_nagumo.toml",
        "obstacle_passive.toml", "obstacle_gray_scott_ard.toml", "obstacle_gray_scott_rd_only.toml",
        "cavity_gray_scott_3d.toml", "obstacle_gray_scott_3d.toml"}) {
    const std::string file = sceneFile(std::string("coupled/") + s);
    CommandResult v = runMorphoflow("validate " + file);
    EXPECT_EQ(v.status, 0) << s << ": " << v.output;
    const bool obstacle = std::string(s).find("obstacle") != std::string::npos;
    const bool threeD = std::string(s).find("3d") != std::string::npos;
    const std::string res = threeD ? (obstacle ? "[12,24,12]" : "[12,12,12]") : obstacle ? "[32,64]" : "[32,32]";
    const std::string rdRes = threeD ? (obstacle ? "[12,24,12]" : "[12,12,12]") : obstacle ? "[48,96]" : "[48,48]";
    std::vector<morphoflow::FieldDump> dumps;
    for (std::string b : {"serial", "tbb"}) {
      const fs::path out = dir / (std::string(s) + b);
      CommandResult r =
          runMorphoflow("run " + file + " --set grid.resolution=" + res + " --set rd.resolution=" + rdRes +
                        " --set time.steps=12 --set output.every=6 --set output.fields=true --backend " + b +
                        " --quiet --out " + out.string());
      ASSERT_EQ(r.status, 0) << s << ": " << r.output;
      morphoflow::FieldDump d;
      std::string err;
      ASSERT_TRUE(morphoflow::readFieldDump((out / "fields" / "000002.exr").string(), &d, &err)) << err;
      dumps.push_back(d);
      nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "run.json"));
      EXPECT_GT(j["coupling"]["fluid_seconds"].get<double>(), 0.0);
    }
    EXPECT_EQ(dumps[0].channels, dumps[1].channels) << s;
    EXPECT_EQ(dumps[0].resolution.size(), threeD ? 3u : 2u);
  }
  fs::remove_all(dir);
}

TEST(Cli, ThreeDScenesRunAtLowResolution) {
  auto dir = tempDir("threed");
  for (const char* s : {"lid_driven_cavity_3d.toml", "flow_past_obstacle_3d.toml"}) {
    std::string res = std::string(s).find("obstacle") != std::string::npos ? "[24,8,8]" : "[12,12,12]";
    CommandResult r =
        runMorphoflow("run " + sceneFile(s) + " --set grid.resolution=" + res +
                      " --set time.duration=0.5 --set output.every=5 --quiet --out " + (dir / s).string());
    ASSERT_EQ(r.status, 0) << s << ": " << r.output;
    EXPECT_TRUE(fs::exists(dir / s / "run.json"));
    EXPECT_TRUE(fs::exists(dir / s / "frames" / "000000.png"));
  }
  fs::remove_all(dir);
}

// Random mutations of a valid scene never crash or hang: exit 0 or 2 only.
TEST(Cli, MutatedScenesNeverCrash) {
  auto dir = tempDir("fuzz");
  std::mt19937 rng(12345);
  const std::string base = kSmall;
  const std::string alphabet = "[]=\"., 0123456789-eE+abcxyz#\n{}";
  for (int i = 0; i < 60; ++i) {
    std::string s = base;
    int edits = 1 + int(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      size_t pos = rng() % s.size();
      switch (rng() % 3) {
        case 0: s[pos] = alphabet[rng() % alphabet.size()]; break;
        case 1: s.erase(pos, 1 + rng() % 6); break;
        default: s.insert(pos, 1, alphabet[rng() % alphabet.size()]);
      }
    }
    fs::path p = writeScene(dir, "m" + std::to_string(i) + ".toml", s);
    CommandResult r = runMorphoflow("run " + p.string() + " --quiet --out " + (dir / "o").string());
    EXPECT_TRUE(r.status == 0 || r.status == 2) << "exit " << r.status << " for:\n" << s << "\n" << r.output;
  }
  fs::remove_all(dir);
}

// A reaction-diffusion-only scene runs, writes frames of the chosen species
// and reports its solvers in run.json.
TEST(Cli, ReactionDiffusionSceneRuns) {
  auto dir = tempDir("rd");
  fs::path p = writeScene(dir, "gs.toml", kGrayScottScene);
  CommandResult r = runMorphoflow("run " + p.string() + " --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "frames" / "000002.png"));
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "out" / "run.json"));
  EXPECT_EQ(j["resolved"]["model"], "gray-scott");
  EXPECT_EQ(j["solvers"]["newton_failures"].get<int>(), 0);
  EXPECT_EQ(j["steps"].get<int>(), 20);
  EXPECT_DOUBLE_EQ(j["resolved"]["cell_size"].get<double>(), 1.0);  // rd scenes default to unit cells
  CommandResult list = runMorphoflow("list models");
  EXPECT_EQ(list.status, 0);
  for (const char* m : {"gray-scott", "brusselator", "oregonator-3layer", "meinhardt-lateral"})
    EXPECT_NE(list.output.find(m), std::string::npos) << m;
  fs::remove_all(dir);
}

// A fused explicit layer too large for the cache steps several steps a pass
// (temporal blocking), up to each frame: its frame after 16 steps is bitwise
// the one a run that writes every step (and so steps one at a time) writes.
TEST(Cli, BlockedStepsGiveTheFramesOfSingleSteps) {
  auto dir = tempDir("rd_blocked");
  fs::path p = writeScene(dir, "gs.toml", std::string(kGrayScottScene) + "images = false\nfields = true\n");
  const std::string blocks =
      " --set grid.resolution=[1536,1536] --set time.steps=16 --set 'rd.integrator=\"explicit\"' ";
  std::vector<morphoflow::FieldDump> dumps;
  for (const char* run : {"--set output.every=8", "--set output.every=1 --frames 16:16"}) {
    const fs::path out = dir / (dumps.empty() ? "blocked" : "single");
    CommandResult r = runMorphoflow("run " + p.string() + blocks + run + " --quiet --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "run.json"));
    EXPECT_EQ(j["steps"].get<int>(), 16);
    EXPECT_GT(j["resolved"]["steps_per_pass"].get<int>(), 1);
    morphoflow::FieldDump d;
    std::string err;
    ASSERT_TRUE(
        morphoflow::readFieldDump((out / "fields" / (dumps.empty() ? "000002.exr" : "000016.exr")).string(), &d, &err))
        << err;
    EXPECT_EQ(d.step, 16);
    dumps.push_back(d);
    if (dumps.size() == 1) {  // the frame between: its step too
      ASSERT_TRUE(morphoflow::readFieldDump((out / "fields" / "000001.exr").string(), &d, &err)) << err;
      EXPECT_EQ(d.step, 8);
    }
  }
  ASSERT_EQ(dumps[0].channels.size(), 2u);
  EXPECT_EQ(dumps[0].channels, dumps[1].channels);
  EXPECT_NE(dumps[0].channels[1], std::vector<float>(dumps[0].channels[1].size(), 0.0f))
      << "the square's v must spread";
  fs::remove_all(dir);
}

// The cosine-lobe scenes (seed 001 eq. 15-16) run at low resolution, and the
// lobes reach the solver: other speeds give another field.
TEST(Cli, CosineLobeScenesRun) {
  auto dir = tempDir("lobes");
  std::vector<morphoflow::FieldDump> dumps;
  for (std::string run : {"kim_lin_witkin_kass", "kim_lin_lobes3", "kim_lin_lobes3 slow"}) {
    const bool slow = run.find("slow") != std::string::npos;
    const std::string name = run.substr(0, run.find(' '));
    const std::string file = sceneFile("rd/seeds/" + name + ".toml");
    CommandResult v = runMorphoflow("validate " + file);
    EXPECT_EQ(v.status, 0) << name << ": " << v.output;
    const fs::path out = dir / (slow ? name + "_slow" : name);
    CommandResult r = runMorphoflow("run " + file + " --set grid.resolution=[32,32] --set domain.size=[0.3125,0.3125]" +
                                    " --set time.steps=40 --set output.every=40 --set output.fields=true" +
                                    (slow ? " --set rd.cosine_lobes.speeds=[0.5,0.5,0.5]" : "") + " --quiet --out " +
                                    out.string());
    ASSERT_EQ(r.status, 0) << name << ": " << r.output;
    nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "run.json"));
    EXPECT_NE(j.dump().find("cosine_lobes"), std::string::npos) << name << ": run.json keeps the resolved scene";
    morphoflow::FieldDump d;
    std::string err;
    ASSERT_TRUE(morphoflow::readFieldDump((out / "fields" / "000001.exr").string(), &d, &err)) << err;
    for (const std::vector<float>& c : d.channels)
      for (float x : c) ASSERT_TRUE(std::isfinite(x)) << name;
    dumps.push_back(d);
  }
  EXPECT_NE(dumps[1].channels, dumps[2].channels) << "the lobe speeds must reach the solver";
  fs::remove_all(dir);
}

// Kim & Lin's painting (seed 001 fig. 3) at 64^2: the stroke's cells hold the
// deposited values, and its direction steering the lobe changes the pattern.
TEST(Cli, PaintedStrokesDepositAndSteerTheLobes) {
  auto dir = tempDir("paint");
  std::vector<morphoflow::FieldDump> dumps;
  for (const char* name : {"kim_lin_paint_deposit", "kim_lin_paint_lobe"}) {
    const std::string file = sceneFile(std::string("rd/seeds/") + name + ".toml");
    CommandResult r =
        runMorphoflow("run " + file + " --set grid.resolution=[64,64] --set time.steps=40 --set output.every=40" +
                      " --set output.fields=true --quiet --out " + (dir / name).string());
    ASSERT_EQ(r.status, 0) << name << ": " << r.output;
    morphoflow::FieldDump d;
    std::string err;
    ASSERT_TRUE(morphoflow::readFieldDump((dir / name / "fields" / "000001.exr").string(), &d, &err)) << err;
    // The spiral starts at (1.25 + 0.12, 1.25) in a 2.5 domain: cell (34, 32) at 64^2 is on it.
    const size_t onStroke = 32 * 64 + 34;
    EXPECT_EQ(d.channels[0][onStroke], 0.5f) << name;
    EXPECT_EQ(d.channels[1][onStroke], 0.25f) << name;
    dumps.push_back(d);
  }
  EXPECT_NE(dumps[0].channels[1], dumps[1].channels[1]) << "theta0 = \"strokes\" must reach the lobes";
  fs::remove_all(dir);
}

// McGraw's generalized diffusion: run.json reports the step's spectral radius
// and the largest step within the bound; `plot propagator` draws fig. 1's
// polar plot (refusing a scene without tensors); the gpu backend refuses it.
TEST(Cli, GeneralizedDiffusionReportsItsSpectralRadiusAndPlotsItsPropagator) {
  auto dir = tempDir("generalized");
  const std::string scene = sceneFile("rd/seeds/mcgraw_fig3_gray_scott_d.toml");
  CommandResult r = runMorphoflow("run " + scene + " --set grid.resolution=[32,32] --set domain.size=[70.4,70.4]" +
                                  " --set time.steps=20 --set output.every=20 --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "out" / "run.json"));
  const nlohmann::json& g = j["resolved"]["generalized_diffusion"];
  EXPECT_LE(g["spectral_radius"]["u"].get<double>(), 1.05);
  EXPECT_GE(g["spectral_radius"]["u"].get<double>(), 1.0);
  EXPECT_GE(g["largest_stable_dt"]["v"].get<double>(), 1.0);
  r = runMorphoflow("plot propagator " + scene + " --out " + (dir / "d.png").string() + " --size 128");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("at 0.0 degrees"), std::string::npos) << r.output;  // (d) peaks on the axes
  morphoflow::FieldDump img;
  std::string err;
  ASSERT_TRUE(morphoflow::readFieldDump((dir / "d.png").string(), &img, &err)) << err;
  EXPECT_EQ(img.resolution, (std::vector<int>{128, 128}));
  size_t ink = 0;
  for (float v : img.channels[0]) ink += v < 0.5f;
  EXPECT_GT(ink, 100u);
  r = runMorphoflow("plot propagator " + sceneFile("rd/gray_scott_pearson.toml") + " --out " +
                    (dir / "x.png").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("no [rd.generalized]"), std::string::npos) << r.output;
  r = runMorphoflow("run " + scene + " --backend gpu --quiet --out " + (dir / "gpu").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("generalized"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// output.normal_map: the normal map read back (an independent PNG decode)
// agrees with the normals of the height EXR written beside it, wrapped on the
// periodic layer, at output.normal_strength.
TEST(Cli, NormalMapsAgreeWithTheirHeightField) {
  auto dir = tempDir("normals");
  CommandResult r = runMorphoflow(
      "run " + sceneFile("rd/gray_scott_pearson.toml") +
      " --set grid.resolution=[48,48] --set domain.size=[0.46875,0.46875] --set time.steps=200" +
      " --set output.every=200 --set output.normal_map=true --set output.normal_strength=6 --quiet --out " +
      (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  morphoflow::FieldDump height, normals;
  std::string err;
  ASSERT_TRUE(morphoflow::readFieldDump((dir / "out" / "height" / "000001.exr").string(), &height, &err)) << err;
  ASSERT_TRUE(morphoflow::readFieldDump((dir / "out" / "normals" / "000001.png").string(), &normals, &err)) << err;
  ASSERT_EQ(height.resolution, (std::vector<int>{48, 48}));
  ASSERT_EQ(normals.resolution, height.resolution);
  ASSERT_GE(normals.channels.size(), 3u);
  const std::vector<float>& hv = height.channels[0];
  float lo = 1, hi = 0;
  for (float v : hv) lo = std::min(lo, v), hi = std::max(hi, v);
  EXPECT_EQ(lo, 0.0f);
  EXPECT_EQ(hi, 1.0f);  // the frames' automatic range
  auto at = [&](int x, int y) { return double(hv[size_t(((y + 48) % 48) * 48 + (x + 48) % 48)]); };
  double worst = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      const double nx = -6.0 * 0.5 * (at(x + 1, y) - at(x - 1, y)), ny = -6.0 * 0.5 * (at(x, y + 1) - at(x, y - 1));
      const double len = std::sqrt(nx * nx + ny * ny + 1.0);
      const size_t i = size_t(y * 48 + x);
      worst = std::max({worst, std::abs(2.0 * normals.channels[0][i] - 1.0 - nx / len),
                        std::abs(2.0 * normals.channels[1][i] - 1.0 - ny / len),
                        std::abs(2.0 * normals.channels[2][i] - 1.0 - 1.0 / len)});
    }
  EXPECT_LT(worst, 1.01 / 255.0);  // 8-bit rounding
  fs::remove_all(dir);
}

// Parameter maps, initial maps and fixed rows reach the solver; output.fields
// dumps every species as float EXR channels named after the model's species.
TEST(Cli, FieldDumpsShowMapsAndFixedRows) {
  auto dir = tempDir("rdfields");
  fs::path p = writeScene(dir, "fixed.toml", R"toml(
[grid]
resolution = [24, 16]
[time]
dt = 0.5
steps = 6
[rd]
model = "brusselator"
boundary = "neumann"
[rd.maps]
beta = "lerp(8, 10, x)"
[rd.initial]
values = [3.0, 3.0]
[rd.initial.maps]
b = "1 + y"
[[rd.fixed]]
where = "j == 0"
values = [0.0, 5.0]
[[rd.fixed]]
where = "j == floor(ny / 2)"
values = [5.0, 0.0]
[[rd.fixed]]
where = "i == 0 && j == 4"
species = ["a"]
values = [7.0]
[output]
every = 3
fields = true
colormap = "red-green"
)toml");
  CommandResult r = runMorphoflow("run " + p.string() + " --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "out" / "run.json"));
  EXPECT_EQ(j["fields_written"].get<int>(), 3);
  EXPECT_TRUE(fs::exists(dir / "out" / "frames" / "000002.png"));
  morphoflow::FieldDump d0, d2;
  std::string err;
  ASSERT_TRUE(morphoflow::readFieldDump((dir / "out" / "fields" / "000000.exr").string(), &d0, &err)) << err;
  ASSERT_TRUE(morphoflow::readFieldDump((dir / "out" / "fields" / "000002.exr").string(), &d2, &err)) << err;
  ASSERT_EQ(d2.resolution, (std::vector<int>{24, 16}));
  EXPECT_EQ(d2.step, 6);
  EXPECT_FLOAT_EQ(float(d2.time), 3.0f);
  auto channel = [](const morphoflow::FieldDump& d, const std::string& name) -> const std::vector<float>& {
    auto it = std::find(d.names.begin(), d.names.end(), name);
    EXPECT_NE(it, d.names.end()) << name;
    return d.channels[size_t(it - d.names.begin())];
  };
  // The initial map: b = 1 + y at cell centres, outside the fixed rows.
  for (int jy = 1; jy < 16; ++jy)
    if (jy != 8) {
      EXPECT_NEAR(channel(d0, "b")[size_t(jy * 24 + 5)], 1.0 + (jy + 0.5) / 16, 1e-6);
    }
  // Fixed rows hold their values after six steps, everywhere along the row.
  for (int x = 0; x < 24; ++x) {
    EXPECT_EQ(channel(d2, "a")[size_t(x)], 0.0f);
    EXPECT_EQ(channel(d2, "b")[size_t(x)], 5.0f);
    EXPECT_EQ(channel(d2, "a")[size_t(8 * 24 + x)], 5.0f);
    EXPECT_EQ(channel(d2, "b")[size_t(8 * 24 + x)], 0.0f);
  }
  // A region that holds one species leaves the other free.
  EXPECT_EQ(channel(d2, "a")[size_t(4 * 24)], 7.0f);
  EXPECT_NE(channel(d2, "b")[size_t(4 * 24)], channel(d0, "b")[size_t(4 * 24)]);
  // The free cells evolved, and differ along x because beta varies along x.
  EXPECT_NE(channel(d2, "a")[size_t(4 * 24 + 2)], channel(d2, "a")[size_t(4 * 24 + 21)]);
  fs::remove_all(dir);
}

// `texton` writes a texture; `analyze` reads it back (or a field dump) and
// reports REG; a regular lattice scores higher than the walked texture.
TEST(Cli, TextonAndAnalyze) {
  auto dir = tempDir("texture");
  auto reg = [](const std::string& out) {
    std::smatch m;
    EXPECT_TRUE(std::regex_search(out, m, std::regex("REG ([0-9.]+)"))) << out;
    return m.empty() ? -1.0 : std::stod(m[1]);
  };
  const std::string lattice = (dir / "lattice.exr").string(), walked = (dir / "walked.png").string();
  CommandResult a = runMorphoflow("texton --size 128 --elements 64 --steps 0 --start regular --out " + lattice);
  ASSERT_EQ(a.status, 0) << a.output;
  CommandResult b =
      runMorphoflow("texton --size 128 --elements 64 --steps 400 --step-size 1 --start regular --out " + walked);
  ASSERT_EQ(b.status, 0) << b.output;
  CommandResult ra = runMorphoflow("analyze " + lattice + " --max-lag 32 --csv " + (dir / "v.csv").string());
  CommandResult rb = runMorphoflow("analyze " + walked + " --max-lag 32");
  ASSERT_EQ(ra.status, 0) << ra.output;
  ASSERT_EQ(rb.status, 0) << rb.output;
  EXPECT_GT(reg(ra.output), reg(rb.output) + 0.2);
  EXPECT_NE(ra.output.find("channel t"), std::string::npos) << ra.output;
  EXPECT_TRUE(fs::exists(dir / "v.csv"));
  EXPECT_EQ(runMorphoflow("analyze " + (dir / "missing.exr").string()).status, 2);
  EXPECT_EQ(runMorphoflow("analyze " + lattice + " --channel zz").status, 2);
  EXPECT_EQ(runMorphoflow("texton --out " + (dir / "x.png").string() + " -p 0.8 -q 0.8").status, 2);
  EXPECT_EQ(runMorphoflow("texton --out " + (dir / "x.txt").string()).status, 2);
  fs::remove_all(dir);
}

// `bench coupling` prints seed 001's Table 1 and writes a Chrome trace whose
// stages name the fluid's and the ARD's parts; bad trace requests exit 2.
TEST(Cli, CouplingBenchWritesAChromeTrace) {
  auto dir = tempDir("bench");
  const fs::path trace = dir / "trace.json", table = dir / "table.json";
  CommandResult r = runMorphoflow("bench coupling --size 32 --seconds 0 --trace " + trace.string() + " --json " +
                                  table.string());
  ASSERT_EQ(r.status, 0) << r.output;
  nlohmann::json t = nlohmann::json::parse(std::ifstream(trace));
  std::set<std::string> stages, groups;
  for (const auto& e : t["traceEvents"]) {
    if (e["ph"] == "X") {
      stages.insert(e["name"].get<std::string>());
      EXPECT_GE(e["dur"].get<double>(), 0.0);
    }
    if (e["name"] == "process_name") groups.insert(e["args"]["name"].get<std::string>());
  }
  for (const char* s : {"forces", "advect", "diffuse", "project", "reaction-diffusion", "advect chemicals"})
    EXPECT_TRUE(stages.count(s)) << s;
  EXPECT_EQ(groups, (std::set<std::string>{"serial 32^2", "tbb 32^2"}));
  nlohmann::json j = nlohmann::json::parse(std::ifstream(table));
  ASSERT_EQ(j.size(), 2u);  // 1 and 2 threads
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(j[k]["threads"].get<int>(), k + 1);
    for (const char* b : {"serial", "tbb"}) {
      const double overhead = j[k][b]["overhead"].get<double>();
      EXPECT_NEAR(overhead, j[k][b]["ms"].get<double>() / j[k]["fluid_only_ms"].get<double>(), 1e-9);
      EXPECT_GT(overhead, 0.0);
    }
    // The steps' compulsory traffic against the triad: a fluid step moves
    // more than its velocity's 8 D bytes a cell, and the coupled step more
    // than the fluid's alone.
    const double triad = j[k]["triad_gb_per_second"].get<double>();
    EXPECT_GT(triad, 0.0);
    const double fluidGBs = j[k]["fluid_only_of_triad"].get<double>() * triad;
    EXPECT_GT(fluidGBs * 1e9 * j[k]["fluid_only_ms"].get<double>() / 1e3, 16.0 * 32 * 32);
    EXPECT_GT(j[k]["tbb"]["of_triad"].get<double>() * triad * j[k]["tbb"]["ms"].get<double>(),
              fluidGBs * j[k]["fluid_only_ms"].get<double>());
  }
  EXPECT_EQ(runMorphoflow("bench fluid --size 32 --seconds 0 --trace " + trace.string()).status, 2);
  // A trace into a folder that is a file is refused before the benchmark runs.
  std::ofstream(dir / "file") << "x";
  EXPECT_EQ(runMorphoflow("bench coupling --size 32 --seconds 0 --trace " + (dir / "file" / "t.json").string()).status,
            2);
  fs::remove_all(dir);
}

// `bench fluid --warm-up N` runs N steps before the timed ones and records
// them in its JSON; the other suites refuse the option (exit 2, naming it).
TEST(Cli, FluidBenchTakesWarmUpSteps) {
  auto dir = tempDir("bench_warm_up");
  const CommandResult warm =
      runMorphoflow("bench fluid --size 32 --seconds 0 --warm-up 7 --json " + (dir / "fluid.json").string());
  ASSERT_EQ(warm.status, 0) << warm.output;
  std::ifstream in(dir / "fluid.json");
  const nlohmann::json rows = nlohmann::json::parse(in);
  ASSERT_FALSE(rows.empty());
  for (const nlohmann::json& c : rows) {
    EXPECT_EQ(c["warm_up_steps"].get<int>(), 7) << c;
    EXPECT_GE(c["steps"].get<int>(), 1) << c;
  }
  const CommandResult rd = runMorphoflow("bench rd --size 32 --seconds 0 --warm-up 7");
  EXPECT_EQ(rd.status, 2) << rd.output;
  EXPECT_NE(rd.output.find("only the fluid suite"), std::string::npos) << rd.output;
  fs::remove_all(dir);
}

// `bench roofline`: the triad's bandwidth with 1 and 2 threads, and every
// kernel's bytes, rate and fraction of it (consistent with each other).
TEST(Cli, RooflineBenchRelatesEveryKernelToTheTriad) {
  auto dir = tempDir("roofline");
  CommandResult r = runMorphoflow("bench roofline --size 48 --seconds 0 --json " + (dir / "r.json").string());
  ASSERT_EQ(r.status, 0) << r.output;
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "r.json"));
  for (const char* t : {"1", "2"}) EXPECT_GT(j["triad"][t].get<double>(), 0.1);
  std::set<std::string> names;
  for (const auto& k : j["kernels"]) {
    names.insert(k["kernel"].get<std::string>());
    const double gbs = k["cell_updates_per_second"].get<double>() * k["bytes_per_cell_update"].get<double>() / 1e9;
    EXPECT_NEAR(k["gb_per_second"].get<double>(), gbs, 1e-9 * gbs);
    EXPECT_NEAR(k["fraction_of_triad"].get<double>(),
                gbs / j["triad"][std::to_string(k["threads"].get<int>())].get<double>(), 1e-9);
  }
  for (const char* k : {"rd explicit (double)", "rd fused (float)", "rd fused 5x5 (float)",
                        "coupling chemical advection", "fluid velocity advection"})
    EXPECT_TRUE(names.count(k)) << k;
  fs::remove_all(dir);
}

// `bench memory`: each case runs in a process of its own and reports its
// peak (above the fixed overhead of a tiny run) and the run's estimate.
TEST(Cli, MemoryBenchReportsEveryCasesPeakAndEstimate) {
  auto dir = tempDir("membench");
  CommandResult r = runMorphoflow("bench memory --size 48 --json " + (dir / "m.json").string());
  ASSERT_EQ(r.status, 0) << r.output;
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "m.json"));
  const double overhead = j["overhead_bytes"].get<double>();
  EXPECT_GT(overhead, 1e6);
  ASSERT_EQ(j["cases"].size(), 7u);
  for (const auto& c : j["cases"]) {
    const double peak = c["peak_bytes"].get<double>();
    EXPECT_GT(peak, 0.8 * overhead) << c.dump();
    EXPECT_NEAR(c["estimate_bytes"].get<double>() / peak, 1.0, 0.3) << c.dump();
    EXPECT_NEAR(c["bytes_per_cell"].get<double>(), (peak - overhead) / c["cells"].get<double>(), 1e-6) << c.dump();
  }
  fs::remove_all(dir);
}

// output.video: with ffmpeg an mp4 holding every frame; without it (or when
// it fails) a warning, exit 0, every frame kept and no half-written video.
TEST(Cli, VideoWithAndWithoutFfmpeg) {
  auto dir = tempDir("video");
  const std::string scene = sceneFile("coupled/cavity_gray_scott.toml");
  const std::string args = " --set grid.resolution=[24,24] --set rd.resolution=[31,31] --set time.steps=30"
                           " --set output.every=3 --set output.video=true --quiet --frames 2:8 --out ";
  auto frames = [](const fs::path& out) {
    int n = 0;
    for (auto& e : fs::directory_iterator(out / "frames")) n += e.path().extension() == ".png";
    return n;
  };
  const char* path = std::getenv("PATH");
  const bool haveFfmpeg = std::system("command -v ffmpeg >/dev/null 2>&1") == 0;
  if (haveFfmpeg) {
    CommandResult r = runMorphoflow("run " + scene + args + (dir / "with").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
    const fs::path mp4 = dir / "with" / "cavity_gray_scott.mp4";
    ASSERT_TRUE(fs::exists(mp4));
    EXPECT_EQ(frames(dir / "with"), 7);
    nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "with" / "run.json"));
    EXPECT_TRUE(j["video"]["written"].get<bool>());
    if (std::system("command -v ffprobe >/dev/null 2>&1") == 0) {
      const std::string probe = "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                                "stream=nb_read_frames,width,height -of csv=p=0 " + mp4.string() + " > " +
                                (dir / "probe.txt").string();
      ASSERT_EQ(std::system(probe.c_str()), 0);
      std::string line;
      std::getline(std::ifstream(dir / "probe.txt"), line);
      EXPECT_EQ(line, "528,528,7");  // frames 2..8; 31 x 31 cells, 17 pixels each (>= 512), padded to even sides
    }
  }
  // No ffmpeg on the PATH.
  const fs::path empty = dir / "emptybin";
  fs::create_directories(empty);
  ASSERT_EQ(setenv("PATH", empty.c_str(), 1), 0);
  CommandResult none = runMorphoflow("run " + scene + args + (dir / "without").string());
  // An ffmpeg that fails.
  const fs::path broken = dir / "brokenbin";
  fs::create_directories(broken);
  std::ofstream(broken / "ffmpeg") << "#!/bin/sh\necho 'no encoder here' >&2\nexit 3\n";
  fs::permissions(broken / "ffmpeg", fs::perms::owner_all);
  ASSERT_EQ(setenv("PATH", (broken.string() + ":" + (path ? path : "")).c_str(), 1), 0);
  CommandResult failed = runMorphoflow("run " + scene + args + (dir / "failed").string());
  if (path) setenv("PATH", path, 1);

  ASSERT_EQ(none.status, 0) << none.output;
  EXPECT_NE(none.output.find("warning: ffmpeg is not on the PATH"), std::string::npos) << none.output;
  EXPECT_EQ(frames(dir / "without"), 7);
  EXPECT_FALSE(fs::exists(dir / "without" / "cavity_gray_scott.mp4"));
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "without" / "run.json"));
  EXPECT_FALSE(j["video"]["written"].get<bool>());

  ASSERT_EQ(failed.status, 0) << failed.output;
  EXPECT_NE(failed.output.find("warning: ffmpeg failed (exit status 3)"), std::string::npos) << failed.output;
  EXPECT_EQ(frames(dir / "failed"), 7);
  EXPECT_FALSE(fs::exists(dir / "failed" / "cavity_gray_scott.mp4"));
  EXPECT_FALSE(fs::exists(dir / "failed" / "cavity_gray_scott.mp4.part"));
  std::string log;
  std::getline(std::ifstream(dir / "failed" / "cavity_gray_scott.ffmpeg.log"), log);
  EXPECT_EQ(log, "no encoder here");
  fs::remove_all(dir);
}

// `morphoflow blender OUT_DIR`: a run's VDB sequence becomes a Blender
// script (valid Python, the sequence's facts in its header); a folder
// without volumes, or with a gap in the sequence, is exit 2 naming it.
TEST(Cli, BlenderWritesTheSetUpOfARunsSequence) {
  auto dir = tempDir("blender_set_up");
  const CommandResult r = runMorphoflow("run " + sceneFile("vfx/plume_gray_scott_3d.toml") +
                                        " --set grid.resolution=[12,20,12] --set rd.resolution=[12,20,12]"
                                        " --set time.duration=0.3 --set output.every=10 --set output.images=false"
                                        " --quiet --out " +
                                        (dir / "run").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const CommandResult b = runMorphoflow("blender " + (dir / "run").string());
  ASSERT_EQ(b.status, 0) << b.output;
  const fs::path script = dir / "run" / "blender_scene.py";
  std::ifstream in(script);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"frames\": 4,"), std::string::npos) << text.substr(0, 2000);
  EXPECT_NE(text.find("\"first\": \"vdb/plume_gray_scott_3d.000000.vdb\""), std::string::npos);
  for (const char* grid : {"\"density\"", "\"color\"", "\"temperature\"", "\"vel\""})
    EXPECT_NE(text.find(grid), std::string::npos) << grid;
  EXPECT_EQ(std::system(("/usr/bin/python3 -m py_compile " + script.string()).c_str()), 0);

  const CommandResult none = runMorphoflow("blender " + dir.string());
  EXPECT_EQ(none.status, 2) << none.output;
  EXPECT_NE(none.output.find("output.vdb = true"), std::string::npos) << none.output;
  fs::remove(dir / "run" / "vdb" / "plume_gray_scott_3d.000002.vdb");
  const CommandResult gap = runMorphoflow("blender " + (dir / "run").string());
  EXPECT_EQ(gap.status, 2) << gap.output;
  EXPECT_NE(gap.output.find("gap"), std::string::npos) << gap.output;
  fs::remove_all(dir);
}
