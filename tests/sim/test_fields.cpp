// The catalogue of fields (scenes/field_catalogue.h), the derived fields
// (sim/derived_fields.h) and a scene's volume inputs (sim/scene_inputs.h),
// in process.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

#include "render/colormap.h"
#include "render/vdb_volume.h"
#include "scenes/field_catalogue.h"
#include "scenes/scene_loader.h"
#include "sim/frame_palette.h"
#include "sim/scene_inputs.h"
#include "sim/simulation_factory.h"
#include "tests/test_support.h"

using namespace morphoflow;
using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

const auto quiet = [](const std::string&) {};

template <int D>
std::unique_ptr<Simulation<D>> stepped(const Scene& scene, int steps) {
  auto sim = makeSimulation<D>(scene, Backend::TBB, quiet, quiet);
  for (int k = 0; k < steps; ++k) sim->step(scene.time.dt);
  return sim;
}

template <int D>
IVec<D> cellsOf(const std::vector<int>& res) {
  IVec<D> c;
  for (int a = 0; a < D; ++a) c[a] = res[size_t(a)];
  return c;
}

// Every field of the catalogue comes back on the grid it names, with the
// components its kind has, finite; the names are unique.
template <int D>
void expectCatalogueHolds(const Scene& scene) {
  SCOPED_TRACE(scene.name);
  auto sim = stepped<D>(scene, 3);
  const FieldCatalogue catalogue = sim->fields();
  const std::vector<std::string> names = sim->fieldNames();
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  for (const FieldInfo& f : catalogue.all()) {
    SCOPED_TRACE(f.name);
    const std::vector<Grid<float, D>> got = sim->field(f.name);
    const size_t components = f.kind == FieldKind::Vector ? D : f.kind == FieldKind::Colour ? 3 : 1;
    ASSERT_EQ(got.size(), components);
    IVec<D> cells = got.front().dims();
    switch (f.grid) {
      case FieldGrid::Chemicals:
        cells = cellsOf<D>(scene.rd.settings.resolution);
        break;
      case FieldGrid::Fluid:
        cells = cellsOf<D>(scene.fluid.resolution);
        break;
      case FieldGrid::Faces:
        cells = cellsOf<D>(scene.fluid.resolution) + IVec<D>(1);
        break;
      case FieldGrid::Shown:
        cells = sim->field(scene.output.field).front().dims();
        break;
      case FieldGrid::Density:
        break;  // (its own test)
    }
    for (const Grid<float, D>& g : got) {
      EXPECT_EQ(g.dims(), cells);
      for (float v : g.values()) ASSERT_TRUE(std::isfinite(v));
      if (f.kind == FieldKind::Mask || f.kind == FieldKind::Solid) {
        for (float v : g.values()) ASSERT_TRUE(v == 0.0f || v == 1.0f);
      }
    }
  }
}

TEST(FieldCatalogue, EveryKindOfSceneAnswersEveryFieldOnItsGrid) {
  expectCatalogueHolds<2>(loadScene(sceneFile("rd/gray_scott_pearson.toml"), {"grid.resolution=[24,24]"}));
  expectCatalogueHolds<2>(loadScene(sceneFile("lid_driven_cavity.toml"), {"grid.resolution=[16,16]"}));
  expectCatalogueHolds<2>(
      loadScene(sceneFile("coupled/cavity_gray_scott.toml"), {"grid.resolution=[16,16]", "rd.resolution=[32,32]"}));
  expectCatalogueHolds<2>(
      loadScene(sceneFile("vfx/plume_gray_scott_2d.toml"), {"grid.resolution=[16,24]", "rd.resolution=[32,48]"}));
  expectCatalogueHolds<3>(
      loadScene(sceneFile("vfx/plume_gray_scott_3d.toml"), {"grid.resolution=[6,10,6]", "rd.resolution=[12,20,12]"}));
  expectCatalogueHolds<2>(
      parseScene("name = \"given\"\n[grid]\nresolution = [16, 16]\n[rd]\nmodel = \"gray-scott\"\n"
                 "[velocity]\nfield = [\"0.1\", \"x - 0.5\"]\n",
                 "given.toml"));
}

// The scene reader takes an output's field from the catalogue's output
// names, and a deposit's from its settable ones.
TEST(FieldCatalogue, TheReaderChecksNamesAgainstIt) {
  const std::string plume = sceneFile("vfx/plume_gray_scott_2d.toml");
  const FieldCatalogue catalogue(loadScene(plume));
  for (const FieldInfo& f : catalogue.all()) {
    SCOPED_TRACE(f.name);
    const std::vector<std::string> set = {"output.field=\"" + f.name + "\""};
    if (f.output) EXPECT_EQ(loadScene(plume, set).output.field, f.name);
    else EXPECT_THROW(loadScene(plume, set), UserError);
  }
  EXPECT_EQ(catalogue.settableNames(), (std::vector<std::string>{"u", "v", fields::kDye, fields::kTemperature}));
  const std::string deposit = "[[deposits]]\nfield = \"speed\"\ncenter = [0.5, 0.5]\nradius = 0.1\nvalue = 1.0\n";
  const std::string text = "[grid]\nresolution = [16, 16]\n[fluid]\nreynolds = 100\n" + deposit;
  try {
    parseScene(text, "deposit.toml");
    FAIL() << "a deposit of speed was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("dye"), std::string::npos) << e.what();
  }
}

// density: output.vdb_density's expression per cell, on the chemicals' grid
// when it names a species, the fluid's fields sampled at their centres.
TEST(DerivedFields, DensityIsTheExpressionOfTheFieldsPerCell) {
  const std::string cavity = sceneFile("coupled/cavity_gray_scott.toml");
  {  // one grid: the expression exactly
    const Scene s = loadScene(cavity, {"grid.resolution=[16,16]", "rd.resolution=[16,16]", "output.vdb=true",
                                       "output.vdb_density=\"v + 2 * speed\""});
    auto sim = stepped<2>(s, 4);
    const Grid<float, 2> d = sim->field(fields::kDensity).front(), v = sim->field("v").front(),
                         speed = sim->field(fields::kSpeed).front();
    double largest = 0;
    for (size_t i = 0; i < d.size(); ++i) {
      EXPECT_FLOAT_EQ(d[i], float(double(v[i]) + 2 * double(speed[i])));
      largest = std::max(largest, double(d[i]));
    }
    EXPECT_GT(largest, 0.0);
  }
  {  // the fluid's speed resampled onto the chemicals' grid, twice as fine: the same mean
    const Scene s = loadScene(cavity, {"grid.resolution=[16,16]", "rd.resolution=[32,32]", "output.vdb=true",
                                       "output.vdb_density=\"speed + 0 * v\""});
    auto sim = stepped<2>(s, 4);
    const Grid<float, 2> d = sim->field(fields::kDensity).front(), speed = sim->field(fields::kSpeed).front();
    EXPECT_EQ(d.dims(), (IVec<2>{32, 32}));
    auto mean = [](const Grid<float, 2>& g) {
      double m = 0;
      for (float x : g.values()) m += x;
      return m / double(g.size());
    };
    EXPECT_NEAR(mean(d), mean(speed), 0.02 * mean(speed));
  }
}

// A patterned smoke scene's default density is the smoke shaped by its
// shown species (kernels/pattern_density.inc): the smoke itself where the
// species is at the top quarter of its range, (1 - c) of it at the bottom
// quarter, in between never more than the smoke; output.vdb_density and
// output.pattern_contrast = 0 give the smoke itself.
TEST(DerivedFields, ThePatternShapesTheSmokeByDefault) {
  const std::string plume = sceneFile("vfx/plume_gray_scott_2d.toml");
  const std::vector<std::string> small{"grid.resolution=[16,24]", "rd.resolution=[16,24]"};
  const double c = 0.7;
  std::vector<std::string> sets = small;
  sets.push_back("output.pattern_contrast=0.7");
  auto sim = stepped<2>(loadScene(plume, sets), 30);
  const Grid<float, 2> d = sim->field(fields::kDensity).front(), smoke = sim->field(fields::kDye).front(),
                       v = sim->field("v").front();
  float lo = v[0], hi = v[0];
  for (float x : v.values()) lo = std::min(lo, x), hi = std::max(hi, x);
  ASSERT_GT(hi, lo);
  size_t top = 0, bottom = 0;
  for (size_t i = 0; i < d.size(); ++i) {
    const double t = (double(v[i]) - lo) / (double(hi) - lo);
    const double tiny = 1e-6 * smoke[i] + 1e-30;  // (float rounding, and subnormal smoke)
    if (t >= 0.75) {
      EXPECT_NEAR(d[i], smoke[i], tiny);
      ++top;
    }
    if (t <= 0.25) {
      EXPECT_NEAR(d[i], (1 - c) * smoke[i], tiny);
      ++bottom;
    }
    EXPECT_LE(d[i], smoke[i] + tiny);
    EXPECT_GE(d[i], (1 - c) * smoke[i] - tiny);
  }
  EXPECT_GT(top, 0u);
  EXPECT_GT(bottom, 0u);
  for (const char* plain : {"output.pattern_contrast=0", "output.vdb_density=\"dye\""}) {
    sets = small;
    sets.push_back(plain);
    if (std::string(plain).find("vdb_density") != std::string::npos) sets.push_back("output.vdb=true");
    auto flat = stepped<2>(loadScene(plume, sets), 30);
    EXPECT_EQ(flat->field(fields::kDensity).front().values(), flat->field(fields::kDye).front().values()) << plain;
  }
}

// active: 1 exactly where the smoke exceeds output.vdb_tolerance, on both
// grids; everywhere with output.vdb_sparse = false.
TEST(DerivedFields, ActiveIsWhereTheSmokeExceedsTheTolerance) {
  const std::string plume = sceneFile("vfx/plume_gray_scott_2d.toml");
  const Scene s = loadScene(
      plume, {"grid.resolution=[16,24]", "rd.resolution=[16,24]", "output.vdb=true", "output.vdb_tolerance=0.05"});
  auto sim = stepped<2>(s, 5);
  const Grid<float, 2> smoke = sim->field(fields::kDye).front();
  for (const std::string& name : {fields::kActive, fields::kActiveChemicals}) {
    const Grid<float, 2> a = sim->field(name).front();
    size_t on = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i], smoke[i] > 0.05 ? 1.0f : 0.0f);
      on += a[i] != 0.0f;
    }
    EXPECT_GT(on, 0u);
    EXPECT_LT(on, a.size());
  }
  const Scene dense = loadScene(
      plume, {"grid.resolution=[16,24]", "rd.resolution=[32,48]", "output.vdb=true", "output.vdb_sparse=false"});
  const Grid<float, 2> all = stepped<2>(dense, 2)->field(fields::kActiveChemicals).front();
  for (float v : all.values()) EXPECT_EQ(v, 1.0f);
}

// color: the frames' palette of the shown field as linear RGB: its largest
// value gets the palette's top colour under an automatic range.
TEST(DerivedFields, ColorIsTheFramesPaletteOfTheShownField) {
  const Scene s = loadScene(sceneFile("rd/gray_scott_pearson.toml"), {"grid.resolution=[24,24]"});
  auto sim = stepped<2>(s, 20);
  const Grid<float, 2> shown = sim->field(s.output.field).front();
  const std::vector<Grid<float, 2>> rgb = sim->field(fields::kColor);
  const size_t top = size_t(std::max_element(shown.values().begin(), shown.values().end()) - shown.values().begin());
  const Rgb8 c = frameImageOptions(s.output, false).palette(1.0);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(rgb[size_t(k)][top], srgbToLinear(c[size_t(k)]));
  const Grid<float, 2> h = sim->field(fields::kHeight).front();
  EXPECT_EQ(h[top], 1.0f);
  for (float v : h.values()) EXPECT_TRUE(v >= 0.0f && v <= 1.0f);
}

// The scene reader records a [velocity] sequence without reading it;
// checkSceneInputs reads its first frame and refuses one with no velocity
// at the key's line and column.
TEST(SceneInputs, TheReaderRecordsAVolumeSequenceAndSimReadsIt) {
  const fs::path dir = tempDir("scene_inputs");
  VolumeGrid g;
  g.name = "not_velocity";
  g.cells = {8, 8, 1};
  g.voxelSize = 1.0 / 8;
  g.values = {std::vector<float>(64, 1.0f)};
  std::ofstream(dir / "flow.000000.vdb", std::ios::binary) << encodeVdb({g}, VolumeMetadata{}, VolumeOptions{});
  const std::string text =
      "[grid]\nresolution = [8, 8]\n[rd]\nmodel = \"gray-scott\"\n[velocity]\n"
      "vdb = \"flow.######.vdb\"\n";
  const Scene s = parseScene(text, (dir / "flow.toml").string());
  ASSERT_EQ(s.inputs.size(), 1u);
  EXPECT_EQ(fs::path(s.inputs[0].path).filename(), "flow.000000.vdb");
  try {
    checkSceneInputs(s);
    FAIL() << "a volume with no velocity was accepted";
  } catch (const UserError& e) {
    EXPECT_EQ(e.where().line, 6);
    EXPECT_EQ(e.where().column, 7);
    EXPECT_NE(std::string(e.what()).find("flow.000000.vdb"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
