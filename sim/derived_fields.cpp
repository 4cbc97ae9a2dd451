#include "sim/derived_fields.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "core/expression.h"
#include "core/parallel.h"
#include "core/sampling.h"
#include "render/colormap.h"
#include "sim/frame_palette.h"
#include "sim/pattern_density.h"
#include "sim/simulation.h"

namespace morphoflow {

namespace {

// Field `f` at the centres of a grid of `cells` over the same domain (of
// width `width`): itself on its own grid, else sampled multilinearly.
template <int D>
class OnCells {
 public:
  OnCells(const Grid<float, D>& f, const IVec<D>& cells, double width)
      : f_(f),
        same_(f.dims() == cells),
        layout_(Layout<D>::cellCentred(width / f.dim(0), f.dims(), {})),
        h_(width / cells[0]) {}
  double operator()(const IVec<D>& k, size_t i) const {
    if (same_) return f_[i];
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = (k[a] + 0.5) * h_;
    return sampleLinear<float, D>(f_, layout_, x);
  }

 private:
  const Grid<float, D>& f_;
  bool same_;
  Layout<D> layout_;
  double h_;
};

// Whether `n` is a whole word of `text` (a name the expression uses).
bool usesName(const std::string& text, const std::string& n) {
  const auto word = [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; };
  for (size_t at = text.find(n); at != std::string::npos; at = text.find(n, at + 1))
    if ((at == 0 || !word(text[at - 1])) && (at + n.size() == text.size() || !word(text[at + n.size()]))) return true;
  return false;
}

// The shown field (output.field) and where each value lies in the frames'
// range: (v - lo) / span.
template <int D>
struct Shown {
  Grid<float, D> f;
  FieldImageOptions io;
  double lo = 0.0, span = 1.0;
  double at(size_t i) const { return (double(f[i]) - lo) / span; }
};

template <int D>
Shown<D> shown(const Simulation<D>& sim) {
  const OutputSettings& o = sim.scene().output;
  const std::string name = shownField(o, sim.species());
  Shown<D> s{sim.field(name).front(), frameImageOptions(o, sim.symmetric(name))};
  const std::array<double, 2> range = valueRange(s.f.data(), s.f.size(), s.io);
  s.lo = range[0];
  s.span = range[1] > range[0] ? range[1] - range[0] : 1.0;
  return s;
}

// The smoke shaped by the shown species, on the species' grid (the smoke
// sampled at its centres): kernels/pattern_density.inc.
template <int D>
std::vector<Grid<float, D>> shapedSmoke(const Simulation<D>& sim) {
  const Shown<D> s = shown(sim);
  const Grid<float, D> dye = sim.field(fields::kDye).front();
  const OnCells<D> smoke(dye, s.f.dims(), sim.scene().fluid.size[0]);
  const double contrast = sim.scene().output.patternContrast;
  Grid<float, D> out(s.f.dims(), 0.0f);
  forEachCell<D>(out.dims(), [&](const IVec<D>& k, size_t i) {
    const double t = s.at(i);
    out[i] = float(patternDensity(smoke(k, i), std::isfinite(t) ? t : 0.0, contrast));
  });
  return {out};
}

template <int D>
std::vector<Grid<float, D>> density(const Simulation<D>& sim) {
  if (sim.scene().output.patternDensity) return shapedSmoke(sim);
  const Scene& scene = sim.scene();
  const std::string& text = scene.output.vdbDensity;
  const FieldCatalogue catalogue(scene);
  const std::vector<std::string> names = catalogue.outputNames();
  if (std::find(names.begin(), names.end(), text) != names.end()) return sim.field(text);
  const Expression e(text, names);
  const double width = scene.fluid.size[0];
  // The fields it uses; its grid is a species' when it uses one, else theirs.
  std::vector<Grid<float, D>> fields(names.size());
  std::optional<IVec<D>> grid, speciesGrid;
  for (size_t v = 0; v < names.size(); ++v)
    if (usesName(text, names[v])) {
      fields[v] = sim.field(names[v]).front();
      if (!grid) grid = fields[v].dims();
      if (v < catalogue.species().size()) speciesGrid = fields[v].dims();  // (the species come first)
    }
  const IVec<D> cells = speciesGrid ? *speciesGrid : grid ? *grid : sim.field(names.back()).front().dims();
  std::vector<std::unique_ptr<OnCells<D>>> at(names.size());
  for (size_t v = 0; v < names.size(); ++v)
    if (!fields[v].empty()) at[v] = std::make_unique<OnCells<D>>(fields[v], cells, width);
  constexpr size_t kMaxNames = 32;  // species (at most five) and five fluid fields
  if (names.size() > kMaxNames) throw std::logic_error("too many fields for output.vdb_density");
  Grid<float, D> out(cells, 0.0f);
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    std::array<double, kMaxNames> values{};
    for (size_t v = 0; v < names.size(); ++v)
      if (at[v]) values[v] = (*at[v])(k, i);
    const double d = e.evaluate(values.data());
    // Not finite (a division by a zero field) or past a float: no density there.
    out[i] = std::abs(d) <= double(std::numeric_limits<float>::max()) ? float(d) : 0.0f;
  });
  return {out};
}

template <int D>
std::vector<Grid<float, D>> color(const Simulation<D>& sim) {
  const Shown<D> s = shown(sim);
  std::vector<Grid<float, D>> rgb(3, Grid<float, D>(s.f.dims(), 0.0f));
  for (size_t i = 0; i < s.f.size(); ++i) {
    const Rgb8 c = s.io.palette(s.at(i));
    for (int k = 0; k < 3; ++k) rgb[size_t(k)][i] = srgbToLinear(c[size_t(k)]);
  }
  return rgb;
}

template <int D>
std::vector<Grid<float, D>> height(const Simulation<D>& sim) {
  Shown<D> s = shown(sim);
  for (size_t i = 0; i < s.f.size(); ++i) s.f[i] = float(std::clamp(s.at(i), 0.0, 1.0));
  return {std::move(s.f)};
}

// The cells of a grid of the scene's (its resolution per axis).
template <int D>
IVec<D> cellsOf(const std::vector<int>& resolution) {
  IVec<D> c;
  for (int a = 0; a < D; ++a) c[a] = resolution[size_t(a)];
  return c;
}

template <int D>
std::vector<Grid<float, D>> smokeMask(const Simulation<D>& sim, const IVec<D>& cells) {
  const OutputSettings& o = sim.scene().output;
  Grid<float, D> m(cells, 1.0f);
  if (!o.vdbSparse) return {m};
  const Grid<float, D> smoke = sim.field(fields::kDye).front();
  const OnCells<D> at(smoke, cells, sim.scene().fluid.size[0]);
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) { m[i] = at(k, i) > o.vdbTolerance ? 1.0f : 0.0f; });
  return {m};
}

}  // namespace

template <int D>
std::vector<Grid<float, D>> derivedField(const Simulation<D>& sim, const std::string& name) {
  if (name == fields::kDensity) return density(sim);
  if (name == fields::kColor) return color(sim);
  if (name == fields::kHeight) return height(sim);
  if (name == fields::kActive) return smokeMask(sim, cellsOf<D>(sim.scene().fluid.resolution));
  if (name == fields::kActiveChemicals) return smokeMask(sim, cellsOf<D>(sim.scene().rd.settings.resolution));
  throw std::invalid_argument("no derived field '" + name + "'");
}

template std::vector<Grid<float, 2>> derivedField<2>(const Simulation<2>&, const std::string&);
template std::vector<Grid<float, 3>> derivedField<3>(const Simulation<3>&, const std::string&);

}  // namespace morphoflow
