// The VDB sink: every frame as DIR/vdb/<scene name>.NNNNNN.vdb (and .nvdb
// with output.nanovdb) for Blender and Houdini: each species as a FloatGrid
// named after it, "density" (output.vdb_density) as a fog volume, "vel" the
// cell-centred velocity (Vec3SGrid, contravariant-relative, domain units per
// unit time), the fluid scalars of output.vdb_fields, and "obstacle" as a
// narrow-band level set when the scene has solids (render/vdb_volume.h).
// With [smoke]: "density" is the smoke, "temperature" beside it, "color" the
// palette applied to output.field (output.vdb_color), and every grid of the
// frame active exactly where the smoke exceeds output.vdb_tolerance.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "run/output_sinks.h"
#include "render/vdb_volume.h"

namespace morphoflow {

template <int D>
class VdbSink : public OutputSink<D> {
 public:
  VdbSink(const std::filesystem::path& out, const Scene& scene);
  void write(const FrameInfo& at, const Simulation<D>& sim) override;
  void report(nlohmann::json* run) const override;
  nlohmann::json state() const override;
  void restore(const nlohmann::json& state) override;
  std::vector<std::string> whereToLook() const override;

 private:
  // The grids of the simulation's current state.
  std::vector<VolumeGrid> grids(const Simulation<D>& sim) const;
  bool smoke() const;  // the scene has [smoke]
  std::filesystem::path dir_;
  const Scene& scene_;
  const std::string hash_;  // the scene's settings hash, for the metadata
  int written_ = 0;
  uintmax_t bytes_ = 0, nanoBytes_ = 0;
  std::map<std::string, uintmax_t>
      clamped_;  // output.vdb_half: voxels per grid beyond half's range, written at its limit
};

}  // namespace morphoflow
