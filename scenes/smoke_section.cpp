// [smoke] (buoyancy, confinement, decay) and [[sources]] (what emits smoke,
// heat and velocity, where and when): fluid/smoke_settings.h.
#include <fmt/format.h>

#include "scenes/scene_reader.h"

namespace morphoflow {

namespace {

// sources.N.motion: the centre per axis as expressions in t, compiled here
// so that an error names its column.
std::vector<std::string> parseMotion(SceneContext& c, const toml::table* t, const std::string& p) {
  Reader& r = c.r;
  const toml::node* n = r.node(t, p, "motion");
  if (!n) return {};
  const toml::array* arr = n->as_array();
  if (!arr || arr->size() != size_t(c.D))
    r.fail(n, p + "motion", fmt::format("expected {} expressions in t, the centre per axis", c.D),
           c.D == 2 ? "e.g. motion = [\"0.5 + 0.2 * sin(t)\", \"0.2\"]" : "");
  return expressionList(r, *arr, p + "motion", {"t"}, "motion", "the variable is t");
}

SmokeSource parseSource(SceneContext& c, const toml::table* t, const std::string& p) {
  Reader& r = c.r;
  SmokeSource src;
  src.region = parseRegion(c, t, p);
  src.motion = parseMotion(c, t, p);
  const bool fromFile = src.region.shape == ObstacleShape::Image || src.region.shape == ObstacleShape::Sdf;
  if (fromFile && !src.motion.empty())
    r.fail(r.node(t, p, "motion"), p + "motion",
           "an image or sdf source is its file stretched over the whole domain: a motion would move nothing",
           "remove motion, or give the source a circle or box shape that moves");
  src.start = r.number(t, p, "start", 0.0, 0.0, 1e12);
  src.end = r.number(t, p, "end", src.end, 0.0, 1e300);
  if (!(src.end > src.start))
    r.fail(r.node(t, p, "end"), p + "end",
           fmt::format("the window ends (t = {:g}) before it starts (t = {:g})", src.end, src.start),
           "give end > start, or leave end out to emit until the run ends");
  src.density = r.number(t, p, "density", 0.0, 0.0, 1e9);
  src.temperature = r.number(t, p, "temperature", 0.0, 0.0, 1e9);
  const toml::node* vn = nullptr;
  const std::vector<double> v = r.numbers(t, p, "velocity", {}, size_t(c.D), size_t(c.D), -1e6, 1e6, false, &vn);
  src.inject = vn != nullptr;
  for (size_t a = 0; a < v.size(); ++a) src.velocity[a] = v[a];
  if (const toml::node* cn = r.node(t, p, "chemicals")) {
    if (c.species.empty())
      r.fail(cn, p + "chemicals", "this scene has no [rd] layer whose species a source could set",
             "add an [rd] section, or drop the key");
    const size_t n = c.species.size();
    src.chemicals = r.numbers(t, p, "chemicals", {}, n, n, -1e12, 1e12);
  }
  if (src.density == 0.0 && src.temperature == 0.0 && !src.inject && src.chemicals.empty())
    r.fail(t, p.substr(0, p.size() - 1), "the source emits nothing",
           "give it a density, a temperature (per unit time), a velocity or chemicals");
  return src;
}

}  // namespace

void parseSmoke(SceneContext& c, Scene* s) {
  Reader& r = c.r;
  const toml::table* t = r.table(c.root, "", "smoke");
  const toml::array* sources = tableArray(r, c.root, "sources");
  if (!t && !sources) return;
  const toml::node* at = t ? static_cast<const toml::node*>(t) : static_cast<const toml::node*>(sources);
  if (!s->hasFluid || c.givenVelocity)
    r.fail(at, t ? "smoke" : "sources", "smoke needs a fluid to carry it",
           "add a [fluid] section (a scene with [velocity] or [rd] alone has none)");
  SmokeSettings& m = s->fluid.smoke;
  m.enabled = true;
  m.weight = r.number(t, "smoke.", "weight", 0.0, -1e9, 1e9);
  m.heat = r.number(t, "smoke.", "buoyancy", 0.0, -1e9, 1e9);
  m.ambient = r.number(t, "smoke.", "ambient", 0.0, -1e9, 1e9);
  m.vorticity = r.number(t, "smoke.", "vorticity", 0.0, 0.0, 1e6);
  m.dissipation = r.number(t, "smoke.", "dissipation", 0.0, 0.0, 1e9);
  m.cooling = r.number(t, "smoke.", "cooling", 0.0, 0.0, 1e9);
  if (sources)
    for (size_t i = 0; i < sources->size(); ++i)
      m.sources.push_back(parseSource(c, sources->get(i)->as_table(), "sources." + std::to_string(i) + "."));
}

}  // namespace morphoflow
