// libFuzzer target for given velocities read from OpenVDB files (`[velocity]
// vdb`): the file as OpenVDB reads it, its grids (`vel_mac`, `vel`, of any
// type, size, transform and metadata), its values (NaN, infinity) and its
// resampling onto a 2D and a 3D scene's faces, stepped three times. An input
// is the one frame's .vdb file.
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz/fuzz_support.h"
#include "render/vdb_volume.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"

using namespace morphoflow;
namespace fs = std::filesystem;

namespace {

constexpr const char* kScene = R"(name = "fuzz_vdb_velocity"
[grid]
resolution = {}
[domain]
size = {}
[time]
dt = 0.01
steps = 3
[rd]
model = "gray-scott"
integrator = "kim-lin"
diffusion = [1.22e-5, 6.1e-6]
[rd.parameters]
F = 0.04
k = 0.06
[velocity]
vdb = "vel.######.vdb"
[coupling]
mode = "ard"
)";

std::string sceneText(int d) {
  std::string s = kScene;
  auto put = [&](const std::string& value) { s.replace(s.find("{}"), 2, value); };
  put(d == 2 ? "[16, 16]" : "[8, 8, 8]");
  put(d == 2 ? "[1.0, 1.0]" : "[1.0, 1.0, 1.0]");
  return s;
}

template <int D>
void stepWith(const fs::path& dir) {
  const Scene scene = parseScene(sceneText(D), (dir / "scene.toml").string());
  auto sim = makeSimulation<D>(scene, Backend::TBB, [](const std::string&) {}, [](const std::string&) {});
  for (int i = 0; i < 3; ++i) sim->step(scene.time.dt);
  sim->checkFinite("after three steps");
}

// A rigid rotation of the unit domain, as morphoflow writes it: staggered
// and cell-centred, 2D and 3D, full floats and half; and one with a NaN, an
// infinity and a value beyond float range in half.
void writeSeeds(const fs::path& dir) {
  int k = 0;
  for (const int d : {2, 3})
    for (const bool staggered : {true, false})
      for (const bool half : {false, true})
        for (const bool hostile : {false, true}) {
        const int n = d == 2 ? 16 : 8;
        VolumeGrid g;
        g.name = staggered ? "vel_mac" : "vel";
        g.kind = staggered ? VolumeGrid::Kind::Staggered : VolumeGrid::Kind::Vector;
        g.cells = {n, n, d == 2 ? 1 : n};
        g.voxelSize = 1.0 / n;
        g.values.assign(3, std::vector<float>(size_t(g.cells[0]) * g.cells[1] * g.cells[2], 0.0f));
        for (int z = 0; z < g.cells[2]; ++z)
          for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
              const size_t i = (size_t(z) * n + y) * n + x;
              g.values[0][i] = float(-((y + 0.5) / n - 0.5));
              g.values[1][i] = float((x + 0.5) / n - 0.5);
            }
        if (hostile) {
          g.values[0][3] = std::nanf("");
          g.values[1][5] = INFINITY;
          g.values[0][7] = 1e30f;
        }
        VolumeMetadata meta;
        meta.time = 0.0;
        meta.domain = {1.0, 1.0, d == 2 ? 0.0 : 1.0};
        VolumeOptions options;
        options.half = half;
        fuzz::writeBytes(dir / ("rotation-" + std::to_string(k++) + ".vdb"), encodeVdb({g}, meta, options));
      }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::writeSeedsIfAsked(writeSeeds);
  fuzz::runOnOneThread();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path dir = fuzz::freshScratch("vdb-velocity");
  fuzz::writeBytes(dir / "vel.000000.vdb", std::string_view(reinterpret_cast<const char*>(data), size));
  fuzz::expectUserErrorsOnly([&] { stepWith<2>(dir); });
  fuzz::expectUserErrorsOnly([&] { stepWith<3>(dir); });
  return 0;
}
