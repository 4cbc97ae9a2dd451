#include "run/vdb_sink.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/output_file.h"
#include "run/output_kinds.h"
#include "run/scene_hash.h"
#include "run/version.h"
#include "scenes/field_catalogue.h"

namespace morphoflow {

namespace {

template <int D>
VolumeGrid volumeGrid(const std::string& name, VolumeGrid::Kind kind, std::vector<Grid<float, D>> components,
                      double domainWidth, int extraVoxels = 0) {
  VolumeGrid g;
  g.name = name;
  g.kind = kind;
  const IVec<D>& n = components.front().dims();
  for (int a = 0; a < D; ++a) g.cells[size_t(a)] = n[a];
  g.voxelSize = domainWidth / (n[0] - extraVoxels);
  for (Grid<float, D>& c : components) g.values.push_back(c.values());
  // A 2D velocity has no z component; a volume's vector has three.
  if (kind == VolumeGrid::Kind::Vector || kind == VolumeGrid::Kind::Staggered)
    while (g.values.size() < 3) g.values.emplace_back(g.values.front().size(), 0.0f);
  return g;
}

}  // namespace

template <int D>
VdbSink<D>::VdbSink(const std::filesystem::path& out, const Scene& scene)
    : dir_(out / kVdbFiles.folder), scene_(scene), hash_(sceneHash(scene)) {
  createOutputFolder(dir_);
}

// The grids of the simulation's current state, each a field of its
// catalogue (scenes/field_catalogue.h) asked for by name.
template <int D>
std::vector<VolumeGrid> VdbSink<D>::grids(const Simulation<D>& sim) const {
  using K = VolumeGrid::Kind;
  const double width = scene_.fluid.size[0];
  const OutputSettings& o = scene_.output;
  const FieldCatalogue catalogue = sim.fields();
  std::vector<VolumeGrid> g;
  for (const std::string& s : sim.species()) g.push_back(volumeGrid<D>(s, K::Scalar, sim.field(s), width));
  g.push_back(volumeGrid<D>(fields::kDensity, K::FogVolume, sim.field(fields::kDensity), width));
  if (catalogue.find(fields::kVelocity))
    g.push_back(volumeGrid<D>("vel", K::Vector, sim.field(fields::kVelocity), width));
  // The MAC faces exactly (cells + 1 voxels per axis), for a later run to read back (docs/vfx.md).
  if (o.vdbMacVelocity) g.push_back(volumeGrid<D>("vel_mac", K::Staggered, sim.field(fields::kVelocityMac), width, 1));
  for (const std::string& f : o.vdbFields) g.push_back(volumeGrid<D>(f, K::Scalar, sim.field(f), width));
  if (smoke() && std::find(o.vdbFields.begin(), o.vdbFields.end(), fields::kTemperature) == o.vdbFields.end())
    g.push_back(volumeGrid<D>(fields::kTemperature, K::Scalar, sim.field(fields::kTemperature), width));
  if (o.vdbColor) g.push_back(volumeGrid<D>(fields::kColor, K::Color, sim.field(fields::kColor), width));
  if (sim.hasObstacles())
    g.push_back(volumeGrid<D>(fields::kObstacle, K::LevelSet, sim.field(fields::kObstacle), width));
  return g;
}

template <int D>
bool VdbSink<D>::smoke() const {
  return scene_.hasFluid && scene_.fluid.smoke.enabled;
}

template <int D>
void VdbSink<D>::write(const FrameInfo& at, const Simulation<D>& sim) {
  const OutputSettings& o = scene_.output;
  std::vector<VolumeGrid> g = grids(sim);
  if (o.vdbHalf)
    for (const auto& [name, n] : clampToHalf(&g)) clamped_[name] += n;
  VolumeMetadata meta;
  meta.frame = at.frame;
  meta.step = at.step;
  meta.time = sim.time();
  meta.dt = at.dt;
  meta.scene = scene_.name;
  meta.version = kVersion;
  meta.settingsHash = hash_;
  for (int a = 0; a < D; ++a) meta.domain[size_t(a)] = scene_.fluid.size[size_t(a)];
  meta.units = "lengths in the scene's domain units (world space fills [0, domain.size]); time in its time units; "
               "vel in domain units per time unit";
  VolumeOptions options;
  options.tolerance = float(o.vdbTolerance);
  options.half = o.vdbHalf;
  // A smoke frame is active where there is smoke, on the fluid's grid and on the chemicals'.
  if (smoke()) {
    options.active.push_back(activeWhere(
        volumeGrid<D>(fields::kActive, VolumeGrid::Kind::Scalar, sim.field(fields::kActive), scene_.fluid.size[0])));
    if (scene_.rd.enabled)
      options.active.push_back(activeWhere(volumeGrid<D>(fields::kActiveChemicals, VolumeGrid::Kind::Scalar,
                                                         sim.field(fields::kActiveChemicals), scene_.fluid.size[0])));
  }
  const std::string stem = fmt::format("{}.{:06d}", safeFileStem(scene_.name), at.frame);
  const std::string vdb = encodeVdb(g, meta, options);
  writeFileAtomically(dir_ / (stem + ".vdb"), vdb);
  bytes_ += vdb.size();
  if (o.nanovdb) {
    const std::string nvdb = encodeNanoVdb(g, meta, options);
    writeFileAtomically(dir_ / (stem + ".nvdb"), nvdb);
    nanoBytes_ += nvdb.size();
  }
  ++written_;
}

template <int D>
void VdbSink<D>::report(nlohmann::json* j) const {
  (*j)["vdb_written"] = written_;
  addBytes(j, "vdb", bytes_);
  if (scene_.output.nanovdb) addBytes(j, "nanovdb", nanoBytes_);
  if (!clamped_.empty()) {
    std::vector<std::string> parts;
    for (const auto& [name, n] : clamped_) parts.push_back(fmt::format("'{}' {} voxels", name, n));
    (*j)["vdb_half_clamped"] = clamped_;
    (*j)["vdb_half_warning"] =
        fmt::format("output.vdb_half: values beyond half's range (65504) were written as +-65504: {} (over all frames; "
                    "set output.vdb_half = false to keep them)",
                    fmt::join(parts, ", "));
  }
}

template <int D>
nlohmann::json VdbSink<D>::state() const {
  nlohmann::json s = {{"written", written_}, {"bytes", bytes_}, {"nano_bytes", nanoBytes_}};
  for (const auto& [name, n] : clamped_)
    s["clamped:" + name] = n;  // (a checkpoint's sink state holds whole numbers only)
  return s;
}

// Blender loads a numbered sequence as one animated volume from its first file.
template <int D>
std::vector<std::string> VdbSink<D>::whereToLook() const {
  const std::filesystem::path first = endFile(dir_, ".vdb", false);
  if (first.empty()) return {};
  const std::string sequence = (dir_ / (safeFileStem(scene_.name) + ".######.vdb")).string();
  return {fmt::format("volumes: {} (Blender: File > Import > OpenVDB, choose {}; or run `blender --python-expr "
                      "\"import bpy; bpy.ops.object.volume_import(filepath='{}')\"`)",
                      sequence, first.filename().string(), first.string())};
}

template <int D>
void VdbSink<D>::restore(const nlohmann::json& s) {
  written_ = stateCount<int>(s, "written");
  bytes_ = stateCount<uintmax_t>(s, "bytes");
  nanoBytes_ = stateCount<uintmax_t>(s, "nano_bytes");
  clamped_.clear();
  for (const auto& [key, n] : s.items())
    if (key.rfind("clamped:", 0) == 0 && n.is_number_unsigned()) clamped_[key.substr(8)] = n.template get<uintmax_t>();
}

template class VdbSink<2>;
template class VdbSink<3>;

}  // namespace morphoflow
