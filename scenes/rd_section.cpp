// [rd]: the reaction-diffusion layer (model, integrator, boundary, parameters, initial state, maps, fixed regions,
// anisotropy, coarse-to-fine), and the check that every spatial field is finite on its grid.
#include "scenes/scene_reader.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rd/model_registry.h"

namespace morphoflow {

namespace {

// theta = "strokes": the direction painted by [[rd.strokes]] (seed 001 sec. 6).
bool isStrokes(const toml::node* n) { return n && n->is_string() && n->value<std::string>().value() == "strokes"; }

double strokeAngle(Reader& r, const toml::table* t, const std::string& p, const std::string& key, const RDScene& R,
                   const toml::node* th) {
  if (R.strokes.empty())
    r.fail(th, p + key, "\"strokes\" takes the direction of [[rd.strokes]], but the scene has none",
           "add a stroke, e.g. [[rd.strokes]] points = [[0.2, 0.5], [0.8, 0.5]]");
  return r.number(t, p, "stroke_angle", 0.0, -1e3, 1e3);
}

// What every part of [rd] reads: the scene's context, the table, the model.
struct RDTable {
  SceneContext& c;
  Reader& r;
  const toml::table& rdt;
  const std::string model;
  const ModelInfo& in;
  const size_t n;  // species
  std::vector<int> speciesList(const toml::node* sp, const std::string& key, bool allowEmpty) const {
    return speciesIndices(r, sp, key, c.species, model, allowEmpty);
  }
};

// The layer's grid: the fluid's, or its own over the same domain.
void parseResolution(const RDTable& t, RDSettings& st) {
  SceneContext& c = t.c;
  st.resolution.clear();
  for (double v : c.res) st.resolution.push_back(int(v));
  st.size = c.size;
  if (c.rdOnly) return;
  // A coupled layer spans the fluid's domain, on its own grid if asked.
  const toml::node* rn = nullptr;
  std::vector<double> rr =
      t.r.numbers(&t.rdt, "rd.", "resolution", c.res, size_t(c.D), size_t(c.D), 4, 8192, false, &rn);
  st.resolution.clear();
  for (int a = 0; a < c.D; ++a) {
    st.resolution.push_back(int(rr[size_t(a)]));
    if (std::abs(c.size[size_t(a)] / rr[size_t(a)] - c.size[0] / rr[0]) > 1e-6 * c.size[0] / rr[0])
      t.r.fail(rn, "rd.resolution", "reaction-diffusion cells must be square over the domain",
               "keep rd.resolution proportional to grid.resolution");
  }
}

// rd.boundary: a coupled layer's follows the fluid's (periodic where it wraps, zero flux at walls).
void parseBoundary(const RDTable& t, const Scene& s, RDSettings& st) {
  Reader& r = t.r;
  const toml::table* rdt = &t.rdt;
  const bool rdOnly = t.c.rdOnly;
  const int D = t.c.D;
  int fluidPeriodic = 0;
  for (int a = 0; a < D; ++a) fluidPeriodic += s.fluid.boundaries.sides[size_t(2 * a)].kind == BoundaryKind::Periodic;
  if (!rdOnly && fluidPeriodic != 0 && fluidPeriodic != D)
    r.fail(rdt, "rd", "a reaction-diffusion layer wraps on every axis or none, but the fluid is periodic on only some",
           "make every boundary periodic, or none");
  const std::string bcDefault = rdOnly || fluidPeriodic == D ? "periodic" : "neumann";
  const std::string bc = r.string(rdt, "rd.", "boundary", bcDefault, {"periodic", "neumann", "dirichlet"});
  if (!rdOnly && (bc == "periodic") != (fluidPeriodic == D))
    r.fail(r.node(rdt, "rd.", "boundary"), "rd.boundary",
           "a coupled layer must wrap exactly where the fluid does (the fluid is " +
               std::string(fluidPeriodic == D ? "periodic" : "walled") + ")",
           "use rd.boundary = \"" + bcDefault + "\" or leave it out");
  st.boundary = bc == "neumann"     ? RDBoundary::Neumann
                : bc == "dirichlet" ? RDBoundary::Dirichlet
                                    : RDBoundary::Periodic;
  st.dirichletValues = r.numbers(rdt, "rd.", "boundary_values", {}, t.n, t.n, -1e12, 1e12);
  if (st.boundary == RDBoundary::Dirichlet && st.dirichletValues.empty())
    r.fail(r.node(rdt, "rd.", "boundary"), "rd.boundary_values",
           "Dirichlet boundaries need boundary_values, one per species", "species: " + join(t.c.species));
}

// The solver's settings: grid, diffusion, integrator, boundary, lookup table,
// linear solver, frozen species and [rd.parameters].
void parseSettings(const RDTable& t, const Scene& s, RDSettings& st) {
  Reader& r = t.r;
  const toml::table* rdt = &t.rdt;
  st.model = t.model;
  parseResolution(t, st);
  st.diffusion = r.numbers(rdt, "rd.", "diffusion", t.in.diffusion, t.n, t.n, 0, 1e12);
  const std::string integ =
      r.string(rdt, "rd.", "integrator", "kim-lin", {"kim-lin", "explicit", "semi-implicit", "crank-nicolson"});
  st.integrator = integ == "explicit"        ? RDIntegrator::ExplicitEuler
                  : integ == "semi-implicit" ? RDIntegrator::SemiImplicit
                  : integ == "crank-nicolson" ? RDIntegrator::CrankNicolson
                                             : RDIntegrator::KimLin;
  parseBoundary(t, s, st);
  st.lookupTable = r.boolean(rdt, "rd.", "lookup_table", false);
  st.lookupSize = int(r.integer(rdt, "rd.", "lookup_size", 256, 2, 4096));
  const std::string ls = r.string(rdt, "rd.", "linear_solver", "mgpcg", {"mgpcg", "icpcg"});
  st.linearSolver = ls == "icpcg" ? RDLinearSolver::ICPCG : RDLinearSolver::MGPCG;
  st.tolerance = r.number(rdt, "rd.", "tolerance", 1e-8, 0, 1, true);
  if (const toml::node* fr = r.node(rdt, "rd.", "frozen")) st.frozen = t.speciesList(fr, "rd.frozen", true);
  // [rd.parameters]: uniform values by name.
  const toml::table* pt = r.table(*rdt, "rd.", "parameters");
  for (const ParameterInfo& p : t.in.parameters)
    st.parameters.push_back(r.number(pt, "rd.parameters.", p.name, p.value, -1e12, 1e12));
}

// [rd.initial] and its maps (species -> spatial field, replacing its uniform value).
void parseInitial(const RDTable& t, RDScene& R) {
  Reader& r = t.r;
  const size_t n = t.n;
  const std::vector<std::string>& species = t.c.species;
  const toml::table* it = r.table(t.rdt, "rd.", "initial");
  RDInitial& I = R.initial;
  I.values = r.numbers(it, "rd.initial.", "values", t.in.initial, n, n, -1e12, 1e12);
  if (const toml::node* nz = r.node(it, "rd.initial.", "noise"); nz && nz->is_number())
    I.noise.assign(n, r.number(it, "rd.initial.", "noise", 0.0, 0, 1e12));
  else
    I.noise = r.numbers(it, "rd.initial.", "noise", std::vector<double>(n, 0.0), n, n, 0, 1e12);
  if (const std::vector<double> range = interval(r, it, "rd.initial.", "random_range", 1e12); !range.empty()) {
    I.randomRange = true;
    I.range[0] = range[0];
    I.range[1] = range[1];
  }
  I.square = r.number(it, "rd.initial.", "square", 0.0, 0, 1);
  I.squareValues = r.numbers(it, "rd.initial.", "square_values", {}, n, n, -1e12, 1e12);
  if (I.square > 0 && I.squareValues.empty())
    r.fail(r.node(it, "rd.initial.", "square"), "rd.initial.square_values",
           "a central square needs square_values, one per species", "species: " + join(species));
  const toml::table* im = it ? r.table(*it, "rd.initial.", "maps") : nullptr;
  if (!im) return;
  for (auto&& [k, v] : *im) {
    const std::string name(k.str());
    auto sp = std::find(species.begin(), species.end(), name);
    if (sp == species.end())
      r.fail(&v, "rd.initial.maps." + name, "not a species of " + t.model, "species: " + join(species));
    r.node(im, "rd.initial.maps.", name);
    R.initialMaps.push_back({int(sp - species.begin()), r.field(&v, "rd.initial.maps." + name, t.c.sceneDir)});
  }
}

// [rd.maps]: parameter -> spatial field (gradients, radial/angular functions,
// images), or "speed", the given velocity's magnitude (seed 004 fig. 24).
void parseParameterMaps(const RDTable& t, RDScene& R) {
  Reader& r = t.r;
  std::vector<std::string> pnames;
  for (const ParameterInfo& p : t.in.parameters) pnames.push_back(p.name);
  const toml::table* mp = r.table(t.rdt, "rd.", "maps");
  if (!mp) return;
  for (auto&& [k, v] : *mp) {
    const std::string name(k.str());
    auto pi = std::find(pnames.begin(), pnames.end(), name);
    if (pi == pnames.end())
      r.fail(&v, "rd.maps." + name, "not a parameter of " + t.model,
             "did you mean '" + nearest(name, pnames) + "'? parameters: " + join(pnames));
    r.node(mp, "rd.maps.", name);
    if (v.is_string() && v.value<std::string>().value() == "speed") {
      if (!t.c.givenVelocity)
        r.fail(&v, "rd.maps." + name, "\"speed\" maps the given velocity's magnitude, but the scene has no [velocity]",
               "add [velocity] field = [...] or vdb = \"...\"");
      R.speedMaps.push_back(int(pi - pnames.begin()));
      continue;
    }
    R.parameterMaps.push_back({int(pi - pnames.begin()), r.field(&v, "rd.maps." + name, t.c.sceneDir)});
  }
}

// [[rd.fixed]]: regions held at fixed values (seed 004 fig. 20).
void parseFixed(const RDTable& t, RDScene& R) {
  Reader& r = t.r;
  r.node(&t.rdt, "rd.", "fixed");
  const toml::node* fx = t.rdt.get("fixed");
  if (!fx) return;
  const toml::array* arr = fx->as_array();
  if (!arr || !arr->is_array_of_tables())
    r.fail(fx, "rd.fixed", "expected [[rd.fixed]] tables with where = \"expression\" and values = [...]");
  for (size_t q = 0; q < arr->size(); ++q) {
    const toml::table* ft = arr->get(q)->as_table();
    const std::string p = "rd.fixed." + std::to_string(q) + ".";
    const toml::node* w = r.node(ft, p, "where");
    if (!w) r.fail(ft, p + "where", "a fixed region needs where = \"expression\" (nonzero inside), e.g. \"j == 0\"");
    RDFixedRegion fr;
    fr.where = r.field(w, p + "where", t.c.sceneDir);
    if (const toml::node* sp = r.node(ft, p, "species")) {
      fr.species = t.speciesList(sp, p + "species", false);
    } else {
      for (size_t k = 0; k < t.n; ++k) fr.species.push_back(int(k));
    }
    const size_t held = fr.species.size();
    if (!r.node(ft, p, "values"))
      r.fail(ft, p + "values", "a fixed region needs values, one per held species", "species: " + join(t.c.species));
    fr.values = r.numbers(ft, p, "values", {}, held, held, -1e12, 1e12);
    R.fixed.push_back(std::move(fr));
  }
}

// The expression `def` standing for a key the table leaves out.
SceneField defaultField(Reader& r, const toml::table* t, const std::string& key, const char* def) {
  SceneField d;
  d.field.expression = def;
  d.where = r.where(t, key);
  d.key = key;
  return d;
}

// [rd.anisotropy]'s direction: theta (an angle field, or the strokes'), a
// vector field per axis, or "velocity".
void parseAnisotropyDirection(const RDTable& t, const toml::table* an, const RDScene& R, RDAnisotropy& A) {
  Reader& r = t.r;
  const std::string p = "rd.anisotropy.";
  const toml::node* th = r.node(an, p, "theta");
  A.thetaFromStrokes = isStrokes(th);
  if (A.thetaFromStrokes) A.strokeAngle = strokeAngle(r, an, p, "theta", R, th);
  const toml::node* dn = r.node(an, p, "direction");
  A.directionFromVelocity = dn && dn->is_string() && dn->value<std::string>().value() == "velocity";
  if (A.directionFromVelocity && !t.c.givenVelocity)
    r.fail(dn, p + "direction",
           "\"velocity\" orients the tensor along the given velocity, but the scene has no [velocity]",
           "add [velocity] field = [...] or vdb = \"...\"");
  if (A.directionFromVelocity && th)
    r.fail(th, p + "theta", "give either theta or direction = \"velocity\", not both", "drop one of them");
  if (A.directionFromVelocity) return;  // a = u / |u| per cell, set by the run from the velocity it samples
  if (dn) {
    if (th)
      r.fail(th, p + "theta", "give either theta (an angle in the xy plane) or direction (a vector field), not both",
             "drop one of them");
    const toml::array* arr = dn->as_array();
    if (!arr || arr->size() != size_t(t.c.D))
      r.fail(
          dn, p + "direction",
          "expected an array of " + std::to_string(t.c.D) + " fields (one per axis), e.g. [\"y - 0.5\", \"x - 0.5\"]");
    for (size_t q = 0; q < arr->size(); ++q)
      A.direction.push_back(r.field(arr->get(q), p + "direction." + std::to_string(q), t.c.sceneDir));
  } else if (!A.thetaFromStrokes) {
    A.theta = th ? r.field(th, p + "theta", t.c.sceneDir) : defaultField(r, an, p + "theta", "0");
  }
}

// [rd.anisotropy]: inhomogeneous anisotropic tensor diffusion (seed 004 eq. 11-19).
void parseAnisotropy(const RDTable& t, RDScene& R) {
  Reader& r = t.r;
  const toml::table* an = r.table(t.rdt, "rd.", "anisotropy");
  if (!an) return;
  RDAnisotropy& A = R.anisotropy;
  A.enabled = true;
  const std::string p = "rd.anisotropy.";
  auto fieldOr = [&](const char* key, const char* def) {
    if (const toml::node* f = r.node(an, p, key)) return r.field(f, p + key, t.c.sceneDir);
    return defaultField(r, an, p + key, def);
  };
  A.lambda1 = fieldOr("lambda1", "1");
  A.lambda2 = fieldOr("lambda2", "1");
  parseAnisotropyDirection(t, an, R, A);
  if (const toml::node* sp = r.node(an, p, "species")) A.species = t.speciesList(sp, p + "species", false);
  A.shape = r.number(an, p, "shape", 0.0, -1e6, 1e6);
  const std::vector<std::string>& species = t.c.species;
  const std::string ss = r.string(an, p, "shape_species", species.front(), species);
  A.shapeSpecies = int(std::find(species.begin(), species.end(), ss) - species.begin());
}

// [rd.cosine_lobes]: Kim & Lin's anisotropy function a(theta) (seed 001 eq. 14-17).
void parseCosineLobes(const RDTable& t, RDScene& R) {
  Reader& r = t.r;
  const toml::table* cl = r.table(t.rdt, "rd.", "cosine_lobes");
  if (!cl) return;
  RDCosineLobes& L = R.lobes;
  L.enabled = true;
  const std::string p = "rd.cosine_lobes.";
  if (R.anisotropy.enabled)
    r.fail(cl, "rd.cosine_lobes", "[rd.cosine_lobes] and [rd.anisotropy] are two anisotropy models; use one",
           "drop one of the two tables");
  L.witkinKass = r.boolean(cl, p, "witkin_kass", false);
  const toml::node* sn = nullptr;
  L.speeds = r.numbers(cl, p, "speeds", {}, L.witkinKass ? 2 : 1, L.witkinKass ? 2 : 64, 0.0, 1e6, L.witkinKass, &sn);
  if (!sn)
    r.fail(cl, p + "speeds",
           L.witkinKass ? "Witkin-Kass lobes need speeds = [a1, a2] (along x, along y)"
                        : "cosine lobes need speeds = [a_1, ..., a_j], one per lobe, e.g. [1.0, 0.25, 1.0, 0.25]");
  if (std::all_of(L.speeds.begin(), L.speeds.end(), [](double v) { return v == 0.0; }))
    r.fail(sn, p + "speeds", "every lobe speed is 0, so the lobed species would not diffuse at all",
           "give at least one lobe a positive speed");
  const toml::node* th = r.node(cl, p, "theta0");
  L.theta0FromStrokes = isStrokes(th);
  if (L.theta0FromStrokes)
    L.strokeAngle = strokeAngle(r, cl, p, "theta0", R, th);
  else
    L.theta0 = th ? r.field(th, p + "theta0", t.c.sceneDir) : defaultField(r, cl, p + "theta0", "0");
  if (const toml::node* sp = r.node(cl, p, "species")) L.species = t.speciesList(sp, p + "species", false);
}

// [rd.coarse_to_fine]: grow the pattern on coarser grids first.
void parseCoarseToFine(const RDTable& t, RDScene& R) {
  Reader& r = t.r;
  const toml::table* cf = r.table(t.rdt, "rd.", "coarse_to_fine");
  if (!cf) return;
  if (!t.c.rdOnly || t.c.givenVelocity)
    r.fail(cf, "rd.coarse_to_fine", "coarse-to-fine growth is for reaction-diffusion-only scenes",
           "drop [rd.coarse_to_fine] from a scene with [fluid] or [velocity]");
  const toml::node* lv = r.node(cf, "rd.coarse_to_fine.", "levels");
  R.coarseLevels = int(r.integer(cf, "rd.coarse_to_fine.", "levels", 2, 1, 8));
  R.coarseSteps = r.integer(cf, "rd.coarse_to_fine.", "steps", 1000, 0, 1'000'000'000);
  R.coarseScaleDt =
      r.boolean(cf, "rd.coarse_to_fine.", "scale_dt", R.settings.integrator == RDIntegrator::ExplicitEuler);
  for (double v : t.c.res) {
    const long cells = long(v);
    if (cells % (1L << R.coarseLevels) != 0 || (cells >> R.coarseLevels) < 4)
      r.fail(lv ? lv : cf, "rd.coarse_to_fine.levels",
             "each coarser grid halves the resolution, so every grid.resolution entry must be divisible by 2^levels "
             "and leave at least 4 cells",
             "use fewer levels or a resolution such as 256");
  }
}

// [rd.perturb]: Gaussian perturbation of parameters, sigma in percent.
void parsePerturb(const RDTable& t, RDScene& R) {
  const toml::table* pp = t.r.table(t.rdt, "rd.", "perturb");
  for (size_t k = 0; k < t.in.parameters.size(); ++k)
    if (t.r.node(pp, "rd.perturb.", t.in.parameters[k].name))
      R.perturb.push_back({int(k), t.r.number(pp, "rd.perturb.", t.in.parameters[k].name, 0.0, 0, 100)});
}

// "cell (i, j[, k])" of the flat index i on a grid of `res` cells.
std::string cellName(size_t i, const std::vector<double>& res) {
  std::ostringstream c;
  c << "cell (" << i % size_t(res[0]) << ", " << (i / size_t(res[0])) % size_t(res[1]);
  if (res.size() == 3) c << ", " << i / size_t(res[0] * res[1]);
  return c.str() + ")";
}

// A spatial field is finite on the layer's grid `res` (a principal
// diffusivity also > 0), and a region holds a cell.
void checkField(const SceneField& f, const std::vector<double>& res, bool region, bool positive = false) {
  const std::vector<double> v = res.size() == 2
                                    ? sampleSpatialField<2>(f.field, IVec<2>(int(res[0]), int(res[1])))
                                    : sampleSpatialField<3>(f.field, IVec<3>(int(res[0]), int(res[1]), int(res[2])));
  size_t inside = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]))
      throw UserError(f.where, f.key, "the field is not finite at " + cellName(i, res),
                      "guard divisions and logarithms, e.g. 1 / max(r, 1e-6)");
    if (positive && !(v[i] > 0.0))
      throw UserError(f.where, f.key,
                      "a principal diffusivity must be > 0 (the tensor positive definite), but it is " +
                          (std::ostringstream() << v[i]).str() + " at " + cellName(i, res),
                      "keep lambda1 and lambda2 positive everywhere, e.g. max(..., 0.1)");
    inside += v[i] != 0.0;
  }
  if (region && inside == 0)
    throw UserError(f.where, f.key, "no cell is inside this region",
                    "the expression must be nonzero somewhere, e.g. \"j == 0\" for the first row");
}

// Every spatial field is finite on the grid, and every fixed region holds a cell.
void checkSpatialFields(const RDScene& R) {
  std::vector<double> res;
  for (int v : R.settings.resolution) res.push_back(v);
  for (const auto& [k, f] : R.initialMaps) checkField(f, res, false);
  for (const auto& [k, f] : R.parameterMaps) checkField(f, res, false);
  for (const RDFixedRegion& fr : R.fixed) checkField(fr.where, res, true);
  if (R.anisotropy.enabled) {
    const RDAnisotropy& A = R.anisotropy;
    checkField(A.lambda1, res, false, true);
    checkField(A.lambda2, res, false, true);
    if (A.direction.empty() && !A.thetaFromStrokes && !A.directionFromVelocity) checkField(A.theta, res, false);
    for (const SceneField& f : A.direction) checkField(f, res, false);
  }
  if (R.lobes.enabled && !R.lobes.theta0FromStrokes) checkField(R.lobes.theta0, res, false);
}

}  // namespace

void parseRD(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  Scene& s = *sp;
  const toml::table* rdt = r.table(c.root, "", "rd");
  if (!rdt) return;
  s.hasFluid = !c.rdOnly;
  RDScene& R = s.rd;
  R.enabled = true;
  const std::vector<std::string> names = modelNames();
  if (!r.node(rdt, "rd.", "model"))
    r.fail(rdt, "rd.model", "a reaction-diffusion scene needs rd.model", "models: " + join(names));
  const std::string model = r.string(rdt, "rd.", "model", "", names);
  const ModelInfo& in = findModel(model)->info();
  c.species = in.species;
  const RDTable t{c, r, *rdt, model, in, in.species.size()};
  parseSettings(t, s, R.settings);
  parseInitial(t, R);
  parseParameterMaps(t, R);
  parseFixed(t, R);
  parseStrokes(c, *rdt, &R);
  parseAnisotropy(t, R);
  parseCosineLobes(t, R);
  parseGeneralized(c, *rdt, &s);
  parseCoarseToFine(t, R);
  parsePerturb(t, R);
  checkSpatialFields(R);
}

}  // namespace morphoflow
