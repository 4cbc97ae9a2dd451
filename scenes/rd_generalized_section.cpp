// [rd.generalized]: McGraw's non-Gaussian diffusion (seed 000): the
// Kramers-Moyal tensors, and the check that the chosen step is stable (the
// exact spectral radius of the step's amplification on this grid).
#include <cmath>

#include <fmt/format.h>

#include "scenes/scene_reader.h"

namespace morphoflow {

namespace {

template <size_t N>
void components(Reader& r, const toml::table* t, const std::string& p, const char* key, const char* names,
                std::array<double, N>* out) {
  const toml::node* n = r.node(t, p, key);
  if (!n) return;
  const toml::array* arr = n->as_array();
  if (!arr || arr->size() != N)
    r.fail(n, p + key,
           fmt::format("{} is the rank-{} tensor: {} unique components ({}){}", key, N - 1, N, names,
                       arr ? fmt::format(", found {}", arr->size()) : std::string()),
           "a symmetric 2D tensor of rank n has n + 1 unique components, x indices before y");
  for (size_t k = 0; k < N; ++k) (*out)[k] = r.checkNumber(arr->get(k), p + key, -1e6, 1e6, false);
}

}  // namespace

void parseGeneralized(SceneContext& c, const toml::table& rdt, Scene* sp) {
  Reader& r = c.r;
  Scene& s = *sp;
  const toml::table* g = r.table(rdt, "rd.", "generalized");
  if (!g) return;
  RDGeneralized& G = s.rd.generalized;
  const std::string p = "rd.generalized.";
  G.enabled = true;
  G.where = r.where(g, "rd.generalized");
  if (c.D != 2)
    r.fail(g, "rd.generalized", "generalized diffusion's 5 x 5 kernels are 2D, and this scene is 3D", "run it in 2D");
  if (s.rd.settings.boundary != RDBoundary::Periodic)
    r.fail(g, "rd.generalized", "generalized diffusion needs a periodic layer (the paper's seamless tiles)",
           "set rd.boundary = \"periodic\"");
  if (s.rd.anisotropy.enabled || s.rd.lobes.enabled)
    r.fail(g, "rd.generalized",
           "[rd.generalized] replaces the diffusion operator, as [rd.anisotropy] and [rd.cosine_lobes] do; use one",
           "drop the other table");
  const std::vector<std::string> presets = kramersMoyalPresets();
  if (r.node(g, p, "preset")) {
    G.preset = r.string(g, p, "preset", "", presets);
    G.tensors = *kramersMoyalPreset(G.preset);
  } else if (!r.node(g, p, "d2") && !r.node(g, p, "d3") && !r.node(g, p, "d4")) {
    r.fail(g, p + "preset",
           "[rd.generalized] needs a preset (Table 2's column: " + join(presets) + ") or tensors d2, d3, d4");
  }
  components(r, g, p, "d2", "Dxx, Dxy, Dyy", &G.tensors.d2);
  components(r, g, p, "d3", "Dxxx, Dxxy, Dxyy, Dyyy", &G.tensors.d3);
  components(r, g, p, "d4", "Dxxxx, Dxxxy, Dxxyy, Dxyyy, Dyyyy", &G.tensors.d4);
  const auto& d2 = G.tensors.d2;
  if (!(d2[0] > 0 && d2[0] * d2[2] - d2[1] * d2[1] > 0))
    r.fail(r.node(g, p, "d2") ? r.node(g, p, "d2") : g, p + "d2",
           "the rank-2 tensor must be positive definite (Dxx > 0, Dxx Dyy > Dxy^2): it is the propagator's covariance",
           "e.g. d2 = [1, 0, 1]");
  G.rotation = r.number(g, p, "rotation", 0.0, -1e3, 1e3);
  G.tensors = rotated(G.tensors, G.rotation);
  G.savitzkyGolaySecond = r.string(g, p, "second_order", "central", {"central", "savitzky-golay"}) == "savitzky-golay";
  if (const toml::node* spn = r.node(g, p, "species"))
    G.species = speciesIndices(r, spn, p + "species", c.species, s.rd.settings.model, false);
  const toml::node* bn = r.node(g, p, "max_spectral_radius");
  G.maxSpectralRadius = r.number(g, p, "max_spectral_radius", G.maxSpectralRadius, 1.0, 10.0);
  // The step's amplification on this grid (exact: the operator is homogeneous and periodic).
  const RDSettings& st = s.rd.settings;
  const double h = st.size[0] / st.resolution[0];
  const GeneralizedDiffusion op(
      G.tensors, st.resolution[0], st.resolution[1], h,
      G.savitzkyGolaySecond ? SecondDerivatives::SavitzkyGolay : SecondDerivatives::CentralDifferences);
  const double theta = diffusionTheta(st.integrator);
  for (size_t k = 0; k < st.diffusion.size(); ++k) {
    const bool mine = G.species.empty() || std::find(G.species.begin(), G.species.end(), int(k)) != G.species.end();
    if (!mine || st.diffusion[k] == 0.0) continue;
    const double rho = op.spectralRadius(s.time.dt * st.diffusion[k], theta);
    if (rho <= G.maxSpectralRadius) continue;
    const double limit = op.largestStableStep(st.diffusion[k], theta, s.time.dt, G.maxSpectralRadius);
    r.fail(
        bn ? bn : g, p + "max_spectral_radius",
        fmt::format(
            "with time.dt = {:g} the {} step of species {} has spectral radius {:.4g} (seed 000 sec. 5), above {:g}: "
            "it would amplify errors",
            s.time.dt,
            theta == 0.0   ? "explicit"
            : theta == 0.5 ? "Crank-Nicolson"
                           : "implicit",
            c.species[k], rho, G.maxSpectralRadius),
        limit > 0 ? fmt::format("use time.dt <= {:.4g}, the largest step within the bound", limit)
                  : std::string("no step keeps it within the bound: raise max_spectral_radius or change the tensors"));
  }
}

}  // namespace morphoflow
