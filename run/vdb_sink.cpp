#include "run/vdb_sink.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "run/output_kinds.h"
#include "run/scene_hash.h"
#include "run/version.h"
#include "core/expression.h"
#include "core/output_file.h"
#include "core/parallel.h"
#include "core/sampling.h"
#include "render/colormap.h"
#include "render/field_image.h"

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

template <int D>
std::vector<VolumeGrid> VdbSink<D>::grids(const Simulation<D>& sim) const {
  using K = VolumeGrid::Kind;
  const double width = scene_.fluid.size[0];
  const OutputSettings& o = scene_.output;
  std::vector<VolumeGrid> g;
  for (const std::string& s : sim.species()) g.push_back(volumeGrid<D>(s, K::Scalar, sim.field(s), width));
  g.push_back(volumeGrid<D>("density", K::FogVolume, densityField(sim), width));
  const std::vector<std::string> names = sim.fieldNames();
  if (std::find(names.begin(), names.end(), "velocity") != names.end())
    g.push_back(volumeGrid<D>("vel", K::Vector, sim.field("velocity"), width));
  // The MAC faces exactly (cells + 1 voxels per axis), for a later run to read back (docs/vfx.md).
  if (o.vdbMacVelocity) g.push_back(volumeGrid<D>("vel_mac", K::Staggered, sim.field("velocity_mac"), width, 1));
  for (const std::string& f : o.vdbFields) g.push_back(volumeGrid<D>(f, K::Scalar, sim.field(f), width));
  if (scene_.hasFluid && scene_.fluid.smoke.enabled &&
      std::find(o.vdbFields.begin(), o.vdbFields.end(), "temperature") == o.vdbFields.end())
    g.push_back(volumeGrid<D>("temperature", K::Scalar, sim.field("temperature"), width));
  if (o.vdbColor) g.push_back(colorGrid(sim, width));
  if (sim.hasObstacles()) g.push_back(volumeGrid<D>("obstacle", K::LevelSet, sim.field("obstacle"), width));
  return g;
}

// The `density` grid: output.vdb_density's field, or its expression of
// fields evaluated per voxel on the chemicals' grid when it names a species
// (the fluid's fields sampled at their centres), else on the fluid's.
template <int D>
std::vector<Grid<float, D>> VdbSink<D>::densityField(const Simulation<D>& sim) const {
  const std::string& text = scene_.output.vdbDensity;
  const std::vector<std::string> all = sim.fieldNames();
  if (std::find(all.begin(), all.end(), text) != all.end()) return sim.field(text);
  std::vector<std::string> names = sim.species();
  for (const char* f : {"speed", "vorticity", "pressure", "dye", "temperature"})
    if (std::find(all.begin(), all.end(), f) != all.end()) names.push_back(f);
  const Expression e(text, names);
  // The fields it uses (a name as a whole word of the text).
  auto used = [&](const std::string& n) {
    for (size_t at = text.find(n); at != std::string::npos; at = text.find(n, at + 1)) {
      const auto word = [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; };
      if ((at == 0 || !word(text[at - 1])) && (at + n.size() == text.size() || !word(text[at + n.size()]))) return true;
    }
    return false;
  };
  std::vector<Grid<float, D>> fields(names.size());
  std::vector<Layout<D>> layouts(names.size());
  IVec<D> cells = sim.field(names.back()).front().dims();
  for (const std::string& s : sim.species())
    if (used(s)) cells = sim.field(s).front().dims();
  for (size_t v = 0; v < names.size(); ++v)
    if (used(names[v])) {
      fields[v] = sim.field(names[v]).front();
      layouts[v] = Layout<D>::cellCentred(scene_.fluid.size[0] / fields[v].dim(0), fields[v].dims(), {});
    }
  const double h = scene_.fluid.size[0] / cells[0];
  Grid<float, D> out(cells, 0.0f);
  constexpr size_t kMaxNames = 32;  // species (at most four) and five fluid fields
  if (names.size() > kMaxNames) throw std::logic_error("too many fields for output.vdb_density");
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    std::array<double, kMaxNames> values{};
    for (size_t v = 0; v < names.size(); ++v) {
      const Grid<float, D>& f = fields[v];
      if (f.empty()) continue;
      if (f.dims() == cells) {
        values[v] = f[i];
      } else {
        Vec<D> x;
        for (int a = 0; a < D; ++a) x[a] = (k[a] + 0.5) * h;
        values[v] = sampleLinear<float, D>(f, layouts[v], x);
      }
    }
    const double d = e.evaluate(values.data());
    // Not finite (a division by a zero field) or past a float: no density there.
    out[i] = std::abs(d) <= double(std::numeric_limits<float>::max()) ? float(d) : 0.0f;
  });
  return {out};
}

// The palette of the frames applied to the shown field, as linear RGB in
// [0, 1] (Blender's Principled Volume reads a grid named `color` by default).
template <int D>
VolumeGrid VdbSink<D>::colorGrid(const Simulation<D>& sim, double width) const {
  const OutputSettings& o = scene_.output;
  const std::string shown = o.colormap == kTwoSpeciesPalette ? sim.species()[0] : o.field;
  const Grid<float, D> f = sim.field(shown).front();
  const FieldImageOptions io = frameImageOptions(o, sim.symmetric(shown));
  const std::array<double, 2> range = valueRange(f.data(), f.size(), io);
  const double span = range[1] > range[0] ? range[1] - range[0] : 1.0;
  std::vector<Grid<float, D>> rgb(3, Grid<float, D>(f.dims(), 0.0f));
  for (size_t i = 0; i < f.size(); ++i) {
    const Rgb8 c = io.palette((double(f[i]) - range[0]) / span);
    for (int k = 0; k < 3; ++k) rgb[size_t(k)][i] = srgbToLinear(c[size_t(k)]);
  }
  return volumeGrid<D>("color", VolumeGrid::Kind::Color, std::move(rgb), width);
}

// Where the smoke exceeds the tolerance, on the grid of `cells` (the
// fluid's, or the chemicals' sampling the smoke at their centres): the one
// topology of a smoke frame's grids of those cells (every voxel with
// output.vdb_sparse = false).
template <int D>
VolumeOptions::ActiveMask VdbSink<D>::smokeMask(const Simulation<D>& sim, const IVec<D>& cells) const {
  const Grid<float, D> smoke = sim.field("dye").front();
  const Layout<D> layout = Layout<D>::cellCentred(scene_.fluid.size[0] / smoke.dim(0), smoke.dims(), {});
  const double h = scene_.fluid.size[0] / cells[0];
  VolumeOptions::ActiveMask m;
  for (int a = 0; a < D; ++a) m.cells[size_t(a)] = cells[a];
  if (D == 2) m.cells[2] = 1;
  m.on.assign(size_t(m.cells[0]) * size_t(m.cells[1]) * size_t(m.cells[2]), 1);
  if (!scene_.output.vdbSparse) return m;
  const bool same = cells == smoke.dims();
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    double s = 0.0;
    if (same) {
      s = smoke[i];
    } else {
      Vec<D> x;
      for (int a = 0; a < D; ++a) x[a] = (k[a] + 0.5) * h;
      s = sampleLinear<float, D>(smoke, layout, x);
    }
    m.on[i] = s > scene_.output.vdbTolerance ? 1 : 0;
  });
  return m;
}

namespace {

// output.vdb_half: a value beyond half's range (65504) would be read back as
// infinity; it is written at the limit instead, and counted per grid.
void clampToHalf(std::vector<VolumeGrid>* grids, std::map<std::string, uintmax_t>* clamped) {
  constexpr float kHalfMax = 65504.0f;
  for (VolumeGrid& g : *grids) {
    if (g.kind == VolumeGrid::Kind::LevelSet) continue;
    uintmax_t n = 0;
    for (std::vector<float>& c : g.values)
      for (float& v : c)
        if (std::abs(v) > kHalfMax) v = std::copysign(kHalfMax, v), ++n;
    if (n > 0) (*clamped)[g.name] += n;
  }
}

}  // namespace

template <int D>
void VdbSink<D>::write(const FrameInfo& at, const Simulation<D>& sim) {
  const OutputSettings& o = scene_.output;
  std::vector<VolumeGrid> g = grids(sim);
  if (o.vdbHalf) clampToHalf(&g, &clamped_);
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
  if (scene_.hasFluid && scene_.fluid.smoke.enabled) {
    options.active.push_back(smokeMask(sim, sim.field("dye").front().dims()));
    if (scene_.rd.enabled) options.active.push_back(smokeMask(sim, sim.field(sim.species()[0]).front().dims()));
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
