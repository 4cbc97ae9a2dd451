// [boundary] (each side of the box) and [inflow] (its profile and speed).
#include "scenes/scene_reader.h"

namespace morphoflow {

BoundaryKind parseBoundary(const std::string& s) {
  if (s == "inflow") return BoundaryKind::Inflow;
  if (s == "outflow") return BoundaryKind::Outflow;
  if (s == "periodic") return BoundaryKind::Periodic;
  return BoundaryKind::Wall;
}

void parseBoundary(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  toml::table& root = c.root;
  Scene& s = *sp;
  const int D = c.D;
  const toml::table* bnd = r.table(root, "", "boundary");
  const char* sideNames[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  const std::vector<std::string> kinds = {"wall", "inflow", "outflow", "periodic"};
  int inflowSide = -1, outflows = 0;
  for (int k = 0; k < 2 * D; ++k) {
    std::string v = r.string(bnd, "boundary.", sideNames[k], "wall", kinds);
    s.fluid.boundaries.sides[size_t(k)].kind = parseBoundary(v);
    if (v == "inflow") {
      if (inflowSide >= 0)
        r.fail(r.node(bnd, "boundary.", sideNames[k]), std::string("boundary.") + sideNames[k],
               "only one side may be an inflow");
      inflowSide = k;
    }
    outflows += v == "outflow";
  }
  for (int a = 0; a < D; ++a) {
    bool lo = s.fluid.boundaries.sides[size_t(2 * a)].kind == BoundaryKind::Periodic;
    bool hi = s.fluid.boundaries.sides[size_t(2 * a + 1)].kind == BoundaryKind::Periodic;
    if (lo != hi)
      r.fail(r.node(bnd, "boundary.", sideNames[2 * a + (lo ? 1 : 0)]),
             std::string("boundary.") + sideNames[2 * a + (lo ? 1 : 0)],
             "a periodic side needs a periodic opposite side");
  }
  if (inflowSide >= 0 && outflows == 0)
    r.fail(r.node(bnd, "boundary.", sideNames[inflowSide]), std::string("boundary.") + sideNames[inflowSide],
           "an inflow needs an outflow side, or the fluid has nowhere to go");

  // [inflow]
  const toml::table* inflow = r.table(root, "", "inflow");
  std::string profile = r.string(inflow, "inflow.", "profile", "parabolic", {"parabolic", "uniform"});
  s.fluid.boundaries.profile = profile == "uniform" ? InflowProfile::Uniform : InflowProfile::Parabolic;
  s.fluid.boundaries.inflowMeanVelocity = r.number(inflow, "inflow.", "mean_velocity", 1.0, -1e6, 1e6);
  s.fluid.inflowDyeStripes = int(r.integer(inflow, "inflow.", "dye_stripes", 0, 0, 4096));

  c.inflowSide = inflowSide;
}

}  // namespace morphoflow
