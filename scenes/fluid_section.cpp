// [fluid] (viscosity or Reynolds number, advection, pressure solver, forces), [dye] and [probes].
#include <fmt/format.h>

#include "fluid/obstacle_motion.h"
#include "scenes/scene_reader.h"

#include <cmath>

namespace morphoflow {

namespace {

// The probes' reference scales: the first obstacle's diameter and frontal
// area with the mean inflow, or with its own speed at the start where it
// moves (a towed body, a paddle's tip), else the domain's width and the
// lid's speed.
void setReferenceScales(const SceneContext& c, double lid, Scene& s) {
  const int D = c.D;
  const std::vector<double>& size = c.size;
  ProbeSettings& pr = s.probes;
  pr.referenceLength = size[0];
  pr.referenceSpeed = lid != 0.0 ? std::abs(lid) : 1.0;
  pr.referenceArea = D == 2 ? size[0] : size[0] * size[2];
  const bool towed = c.inflowSide < 0 && !s.fluid.obstacles.empty() && movesAtAll(s.fluid.obstacles.front()) &&
                     obstacleSpeedBound(s.fluid.obstacles.front(), D, s.timeline.obstacles.front().start) > 0.0;
  if (c.inflowSide < 0 && !towed) return;
  int flow = c.inflowSide / 2;
  if (towed) {
    const ObstacleSpec& o = s.fluid.obstacles.front();
    RigidMotion m;
    placedAt(o, D, s.timeline.obstacles.front().start, &m);
    pr.referenceSpeed = obstacleSpeedBound(o, D, s.timeline.obstacles.front().start);
    flow = 0;  // the axis it moves along most
    for (int a = 1; a < D; ++a)
      if (std::abs(m.velocity[size_t(a)]) > std::abs(m.velocity[size_t(flow)])) flow = a;
  } else {
    pr.referenceSpeed = std::abs(s.fluid.boundaries.inflowMeanVelocity);
  }
  if (s.fluid.obstacles.empty()) return;
  const ObstacleSpec& o = s.fluid.obstacles.front();
  int across = flow == 1 ? 0 : 1;
  if (o.shape == ObstacleShape::Box) {
    pr.referenceLength = 2 * o.halfSize[size_t(across)];
    pr.referenceArea = 1.0;
    for (int b = 0; b < D; ++b)
      if (b != flow) pr.referenceArea *= 2 * o.halfSize[size_t(b)];
  } else if (o.shape == ObstacleShape::Circle || o.shape == ObstacleShape::Sphere) {
    pr.referenceLength = 2 * o.radius;
    if (D == 2)
      pr.referenceArea = 2 * o.radius;
    else
      pr.referenceArea = o.shape == ObstacleShape::Sphere ? M_PI * o.radius * o.radius : 2 * o.radius * size[2];
  }
}

// fluid.viscosity, or fluid.reynolds over the reference scales (a --set of
// one replaces the other given in the file).
void parseViscosity(const SceneContext& c, const toml::table* fluid, Scene& s) {
  Reader& r = c.r;
  const ProbeSettings& pr = s.probes;
  const toml::node* reNode = r.node(fluid, "fluid.", "reynolds");
  const toml::node* nuNode = r.node(fluid, "fluid.", "viscosity");
  if (reNode && nuNode && c.overrideLocs.count("fluid.reynolds") == c.overrideLocs.count("fluid.viscosity"))
    r.fail(reNode, "fluid.reynolds", "give either fluid.reynolds or fluid.viscosity, not both");
  if (!reNode || (nuNode && c.overrideLocs.count("fluid.viscosity"))) {
    s.fluid.viscosity = r.number(fluid, "fluid.", "viscosity", 1e-3, 0, 1e9);
    s.reynolds = s.fluid.viscosity > 0 ? pr.referenceSpeed * pr.referenceLength / s.fluid.viscosity : 0.0;
    return;
  }
  s.reynolds = r.number(fluid, "fluid.", "reynolds", 100.0, 0, 1e12, true);
  s.fluid.viscosity = pr.referenceSpeed * pr.referenceLength / s.reynolds;
  // The viscosity the Reynolds number implies is bounded like a given one.
  if (!(s.fluid.viscosity <= 1e9))
    r.fail(reNode, "fluid.reynolds",
           fmt::format("Re = {:g} gives a viscosity of {:g} (speed {:g} x length {:g} / Re), more than 1e9", s.reynolds,
                       s.fluid.viscosity, pr.referenceSpeed, pr.referenceLength),
           fmt::format("use a Reynolds number of at least {:g}", pr.referenceSpeed * pr.referenceLength / 1e9));
}

// The advection scheme, the pressure solver and the body forces.
void parseSchemes(const SceneContext& c, const toml::table* fluid, Scene& s) {
  Reader& r = c.r;
  const size_t D = size_t(c.D);
  std::string adv = r.string(fluid, "fluid.", "advection", "maccormack", {"semi-lagrangian", "maccormack", "bfecc"});
  s.fluid.advection = adv == "semi-lagrangian" ? AdvectionScheme::SemiLagrangian
                      : adv == "bfecc"         ? AdvectionScheme::Bfecc
                                               : AdvectionScheme::MacCormack;
  std::string ps = r.string(fluid, "fluid.", "pressure_solver", "mgpcg", {"mgpcg", "icpcg", "multigrid"});
  s.fluid.pressureSolver = ps == "icpcg"       ? PressureSolver::ICPCG
                           : ps == "multigrid" ? PressureSolver::Multigrid
                                               : PressureSolver::MGPCG;
  s.fluid.pressureTolerance = r.number(fluid, "fluid.", "pressure_tolerance", 1e-6, 0, 1, true);
  s.fluid.pressureMaxIterations = int(r.integer(fluid, "fluid.", "pressure_max_iterations", 500, 1, 100000));
  std::vector<double> force = r.numbers(fluid, "fluid.", "force", std::vector<double>(D, 0.0), D, D, -1e9, 1e9);
  for (size_t a = 0; a < D; ++a) s.fluid.force[a] = force[a];
  s.fluid.buoyancy = r.number(fluid, "fluid.", "buoyancy", 0.0, -1e9, 1e9);
  std::vector<double> up(D, 0.0);
  up[1] = 1.0;
  up = r.numbers(fluid, "fluid.", "buoyancy_direction", up, D, D, -1e9, 1e9);
  for (size_t a = 0; a < D; ++a) s.fluid.buoyancyDirection[a] = up[a];
}

// [dye] and [probes].
void parseDyeAndProbes(const SceneContext& c, Scene& s) {
  Reader& r = c.r;
  const toml::table* dye = r.table(c.root, "", "dye");
  s.dye.initial = r.string(dye, "dye.", "initial", "none", {"none", "stripes", "checker"});
  s.dye.stripes = int(r.integer(dye, "dye.", "stripes", 8, 1, 4096));
  ProbeSettings& pr = s.probes;
  const toml::table* probes = r.table(c.root, "", "probes");
  pr.centerlines = r.boolean(probes, "probes.", "centerlines", false);
  pr.forces = r.boolean(probes, "probes.", "forces", false);
  if (pr.forces && s.fluid.obstacles.empty())
    r.fail(r.node(probes, "probes.", "forces"), "probes.forces", "there is no obstacle to measure forces on");
  pr.strouhalStart = r.number(probes, "probes.", "strouhal_start", -1.0, -1.0, 1e12);
}

}  // namespace

void parseFluid(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  Scene& s = *sp;
  const toml::table* fluid = r.table(c.root, "", "fluid");
  s.fluid.density = r.number(fluid, "fluid.", "density", 1.0, 0, 1e9, true);
  double lid = r.number(fluid, "fluid.", "lid_velocity", 0.0, -1e6, 1e6);
  if (lid != 0.0) {
    if (s.fluid.boundaries.sides[3].kind != BoundaryKind::Wall)
      r.fail(r.node(fluid, "fluid.", "lid_velocity"), "fluid.lid_velocity",
             "the lid is the y_max side, which must be a wall");
    s.fluid.boundaries.sides[3].wallVelocity = {lid, 0.0, 0.0};
  }
  setReferenceScales(c, lid, s);
  parseViscosity(c, fluid, s);
  parseSchemes(c, fluid, s);
  parseDyeAndProbes(c, s);
}

}  // namespace morphoflow
