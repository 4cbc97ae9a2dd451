// [coupling]: how the fluid carries the reaction-diffusion layer.
#include "scenes/scene_reader.h"

namespace morphoflow {

void parseCoupling(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  toml::table& root = c.root;
  Scene& s = *sp;
  const std::vector<std::string>& species = c.species;
  if (const toml::table* ct = r.table(root, "", "coupling")) {
    if (!s.rd.enabled || !(s.hasFluid || s.velocity.enabled))
      r.fail(ct, "coupling",
             "[coupling] joins a [fluid] (or a given [velocity]) and an [rd] layer, and this scene lacks one of them",
             "add the missing table or drop [coupling]");
  }
  if (s.rd.enabled && (s.hasFluid || s.velocity.enabled)) {
    const toml::table* ct = r.table(root, "", "coupling");
    CouplingScene& C = s.coupling;
    C.enabled = true;
    C.mode = couplingModeNamed(r.string(ct, "coupling.", "mode", "ard", {"ard", "passive", "rd-only"}));
    C.interpolation = interpolationNamed(
        r.string(ct, "coupling.", "interpolation", "linear", {"linear", "cubic", "bspline", "bfecc"}));
    C.rdTimeScale = r.number(ct, "coupling.", "rd_time_scale", 1.0, 0, 1e9, true);
    const size_t n = species.size();
    C.inflowValues = r.numbers(ct, "coupling.", "inflow_values", s.rd.initial.values, n, n, -1e12, 1e12);
    C.solidValues = r.numbers(ct, "coupling.", "solid_values", std::vector<double>(n, 0.0), n, n, -1e12, 1e12);
    const toml::node* mask = r.node(ct, "coupling.", "smoke_mask");
    if (mask && !(s.hasFluid && s.fluid.smoke.enabled))
      r.fail(mask, "coupling.smoke_mask", "this scene has no smoke to mask the pattern with",
             "add [smoke] and [[sources]], or drop coupling.smoke_mask");
    C.smokeMask = mask ? r.number(ct, "coupling.", "smoke_mask", 0.0, 0.0, 1e12) : -1.0;
    C.smokeValues = r.numbers(ct, "coupling.", "smoke_values", s.rd.initial.values, n, n, -1e12, 1e12);
  }
}

}  // namespace morphoflow
