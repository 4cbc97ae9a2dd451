// [velocity]: a given velocity field carrying the [rd] layer in place of a
// fluid (seed 004 sec. 3, fig. 24): analytic expressions, or a VDB sequence
// whose frames are found and recorded here (sim/scene_inputs.h reads them).
#include "coupling/given_velocity.h"
#include "scenes/scene_reader.h"

namespace morphoflow {

namespace {

// velocity.field: one expression per axis in x, y, z (domain units) and t.
void parseVelocityField(SceneContext& c, const toml::node* fn, VelocityScene& V) {
  Reader& r = c.r;
  const std::string p = "velocity.";
  const std::string axes = c.D == 2 ? "two" : "three";
  V.where = r.where(fn, p + "field");
  V.key = p + "field";
  const toml::array* arr = fn->as_array();
  if (!arr || arr->size() != size_t(c.D))
    r.fail(fn, p + "field",
           "expected " + axes + " expressions, one per axis, in x, y" + (c.D == 3 ? ", z" : "") +
               " (domain units) and t" + (arr ? ", found " + std::to_string(arr->size()) : ""),
           c.D == 2 ? "e.g. field = [\"-(y - 0.5)\", \"x - 0.5\"] (a rigid rotation about the centre of a unit domain)"
                    : "");
  V.field = expressionList(r, *arr, p + "field", ExpressionVelocity<3>::variables(), "velocity",
                           "the variables are x, y, z (domain units) and t");
}

// velocity.vdb: a sequence of volumes, each frame noted as an input.
void parseVelocityVdb(SceneContext& c, const toml::table* vt, const toml::node* vn, Scene& s) {
  Reader& r = c.r;
  const std::string p = "velocity.";
  VelocityScene& V = s.velocity;
  V.where = r.where(vn, p + "vdb");
  V.key = p + "vdb";
  const std::string file = r.string(vt, p, "vdb", "");
  std::filesystem::path fp(file);
  if (fp.is_relative()) fp = c.sceneDir / fp;
  V.vdb = fp.string();
  try {
    const std::vector<VelocityFrame> frames = findVelocityFrames(V.vdb, V.frameTime);
    for (const VelocityFrame& f : frames) r.noteInput(f.path, vn, p + "vdb");
  } catch (const VelocityFileError& e) {
    r.fail(vn, p + "vdb", e.path() + ": " + e.what(), kVelocityFilesHint);
  }
}

}  // namespace

void parseVelocity(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  Scene& s = *sp;
  const toml::table* vt = r.table(c.root, "", "velocity");
  if (!vt) return;
  const std::string p = "velocity.";
  if (!s.rd.enabled)
    r.fail(vt, "velocity", "[velocity] carries a reaction-diffusion layer, and this scene has no [rd]",
           "add [rd] model = \"...\"");
  if (c.root.contains("fluid"))
    r.fail(vt, "velocity", "[velocity] gives the flow in place of a fluid, and this scene has a [fluid]",
           "drop one of [velocity] and [fluid]");
  VelocityScene& V = s.velocity;
  V.enabled = true;
  const toml::node* fn = r.node(vt, p, "field");
  const toml::node* vn = r.node(vt, p, "vdb");
  const toml::node* pn = r.node(vt, p, "python");
  V.python = pn && r.boolean(vt, p, "python", false);
  if (V.python) {  // the velocity comes from the Python module (Simulation.set_velocity)
    if (fn || vn)
      r.fail(fn ? fn : vn, p + (fn ? "field" : "vdb"),
             "python = true takes the velocity from Python: give no field or vdb");
    V.where = r.where(pn, p + "python");
    V.key = p + "python";
  }
  if (fn && vn) r.fail(vn, p + "vdb", "give either field (expressions) or vdb (a volume sequence), not both");
  if (!fn && !vn && !V.python)
    r.fail(vt, p + "field",
           "[velocity] needs field = [\"u(x, y, t)\", \"v(x, y, t)\"], vdb = \"path/name.####.vdb\" or python = true");
  if (fn) parseVelocityField(c, fn, V);
  V.frameTime = r.number(vt, p, "frame_time", 0.0, 0.0, 1e12);
  if (vn) parseVelocityVdb(c, vt, vn, s);
  const toml::node* rn = nullptr;
  const std::vector<double> range = r.numbers(vt, p, "speed_range", {0.0, 1.0}, 2, 2, -1e12, 1e12, false, &rn);
  V.speedRange[0] = range[0];
  V.speedRange[1] = range[1];
  V.referenceSpeed = r.number(vt, p, "reference_speed", 0.0, 0.0, 1e12);
}

}  // namespace morphoflow
