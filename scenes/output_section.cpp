// [output]: frames (field, palette, range, format), field dumps and video.
#include <algorithm>
#include <cctype>

#include "core/expression.h"
#include "scenes/field_catalogue.h"
#include "scenes/scene_reader.h"

#include "render/colormap.h"

namespace morphoflow {

namespace {

// output.vdb_density: a field's name, or an expression of fields (e.g. "dye *
// v / 0.3": the smoke with the pattern cut into it), compiled here so that an
// error names its column.
std::string parseVdbDensity(Reader& r, const toml::table* out, const std::string& byDefault,
                            const std::vector<std::string>& fields) {
  std::string density = r.string(out, "output.", "vdb_density", byDefault);
  const bool name = !density.empty() && std::all_of(density.begin(), density.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
  });
  if (name)  // a single name must be a field's (the nearest is suggested)
    return r.string(out, "output.", "vdb_density", byDefault, fields);
  const toml::node* dn = r.node(out, "output.", "vdb_density");
  try {
    if (Expression(density, fields).constant())
      r.fail(dn, "output.vdb_density", "a constant density fills the box", "name a field, or an expression of fields");
  } catch (const ExpressionError& e) {
    SourceLocation at = r.where(dn, "output.vdb_density");
    if (at.line > 0) at.column += 1 + int(e.column());
    throw UserError(at, "output.vdb_density", std::string("neither a field nor an expression of fields: ") + e.what(),
                    "the fields are " + join(fields));
  }
  return density;
}

// output.pattern_contrast: with smoke and a pattern, the density is by
// default the smoke shaped by the shown species (kernels/pattern_density.inc).
void parsePatternDensity(Reader& r, const toml::table* out, bool patterned, OutputSettings& o) {
  const toml::node* pc = r.node(out, "output.", "pattern_contrast");
  const toml::node* given = r.node(out, "output.", "vdb_density");
  if (pc && !patterned)
    r.fail(pc, "output.pattern_contrast",
           "it shapes a smoke's density by the species it shows; this scene has no [smoke], no [rd], or "
           "shows no species (output.field)",
           "drop output.pattern_contrast, or show a species");
  if (pc && given)
    r.fail(pc, "output.pattern_contrast", "output.vdb_density is given, and it replaces the shaped smoke",
           "drop one of output.pattern_contrast and output.vdb_density");
  o.patternContrast = r.number(out, "output.", "pattern_contrast", o.patternContrast, 0.0, 1.0);
  o.patternDensity = patterned && !given;
}

// output.vdb and its options: every named field must be one the scene has.
void parseVdbOutput(SceneContext& c, const toml::table* out, Scene& s) {
  Reader& r = c.r;
  OutputSettings& o = s.output;
  o.vdb = r.boolean(out, "output.", "vdb", false);
  // With [smoke]: the smoke is the density, and the frame is sparse where
  // there is none (every grid active where the smoke exceeds the tolerance).
  const bool smoke = s.hasFluid && s.fluid.smoke.enabled;
  const FieldCatalogue catalogue(s);
  const std::vector<std::string> fluidScalars = catalogue.fluidOutputNames();
  o.vdbDensity = parseVdbDensity(r, out, smoke ? fields::kDye : o.field, catalogue.outputNames());
  const bool showsSpecies = std::find(c.species.begin(), c.species.end(), o.field) != c.species.end();
  parsePatternDensity(r, out, smoke && s.rd.enabled && showsSpecies, o);
  if (const toml::node* vf = r.node(out, "output.", "vdb_fields")) {
    const toml::array* arr = vf->as_array();
    if (!arr) r.fail(vf, "output.vdb_fields", "expected an array of field names, e.g. [\"speed\", \"vorticity\"]");
    if (!s.hasFluid && !arr->empty())
      r.fail(vf, "output.vdb_fields", "this scene has no fluid, so it has none of the fluid fields",
             "drop output.vdb_fields (its species are written anyway)");
    for (const toml::node& e : *arr) {
      auto name = e.value<std::string>();
      if (!name || std::find(fluidScalars.begin(), fluidScalars.end(), *name) == fluidScalars.end())
        r.fail(&e, "output.vdb_fields", "expected names of fluid fields: " + join(fluidScalars),
               name ? "did you mean '" + nearest(*name, fluidScalars) + "'?" : std::string());
      o.vdbFields.push_back(*name);
    }
  }
  o.vdbTolerance = r.number(out, "output.", "vdb_tolerance", smoke ? 1e-3 : 0.0, 0.0, 1e30);
  o.vdbColor = r.boolean(out, "output.", "vdb_color", smoke);
  const toml::node* sparse = r.node(out, "output.", "vdb_sparse");
  o.vdbSparse = r.boolean(out, "output.", "vdb_sparse", smoke);
  if (sparse && o.vdbSparse && !smoke)
    r.fail(sparse, "output.vdb_sparse", "a sparse volume is active where there is smoke, and this scene has no [smoke]",
           "use output.vdb_tolerance to make voxels near 0 inactive");
  o.vdbHalf = r.boolean(out, "output.", "vdb_half", false);
  o.nanovdb = r.boolean(out, "output.", "nanovdb", false);
  const toml::node* mac = r.node(out, "output.", "vdb_mac_velocity");
  o.vdbMacVelocity = r.boolean(out, "output.", "vdb_mac_velocity", false);
  if (o.vdbMacVelocity && !s.hasFluid)
    r.fail(mac, "output.vdb_mac_velocity", "this scene has no fluid, so it has no velocity of its own to write",
           "drop output.vdb_mac_velocity");
  if (!o.vdb)
    for (const char* k : {"vdb_density", "vdb_fields", "vdb_tolerance", "vdb_half", "nanovdb", "vdb_mac_velocity",
                          "vdb_color", "vdb_sparse"})
      if (const toml::node* n = r.node(out, "output.", k); n && !(n->is_boolean() && !n->value<bool>().value()))
        r.fail(n, std::string("output.") + k, "only applies with output.vdb = true",
               "add output.vdb = true or drop it");
}

// The frames' palette: output.colormap or output.gradient, and output.range.
void parsePalette(const SceneContext& c, const toml::table* out, OutputSettings& o) {
  Reader& r = c.r;
  o.colormap =
      r.string(out, "output.", "colormap", o.field == fields::kVorticity ? "coolwarm" : "viridis", colormapNames());
  if (o.colormap == kTwoSpeciesPalette && c.species.size() < 2)
    r.fail(r.node(out, "output.", "colormap"), "output.colormap",
           std::string(kTwoSpeciesPalette) +
               " shows two reaction-diffusion species (the first in red, the second in green)",
           "use it with an [rd] model of two or more species, or pick a scalar palette");
  if (const toml::node* g = r.node(out, "output.", "gradient")) {
    const toml::array* arr = g->as_array();
    if (!arr || arr->size() < 2)
      r.fail(g, "output.gradient",
             "expected an array of two or more colours, e.g. [\"#000000\", \"#ff8800\", \"#ffffff\"]");
    for (const toml::node& e : *arr) {
      Rgb8 colour;
      auto text = e.value<std::string>();
      if (!text || !parseHexColour(*text, &colour))
        r.fail(&e, "output.gradient", "expected a colour as \"#rrggbb\"", "e.g. \"#ff8800\" for orange");
      o.gradient.push_back(colour);
    }
  }
  if (const std::vector<double> range = interval(r, out, "output.", "range", 1e30); !range.empty()) {
    o.autoRange = false;
    o.range[0] = range[0];
    o.range[1] = range[1];
  }
}

// How frames show the field: the 3D view, the image size, the slice, and
// 2D normal and height maps.
void parseView(const SceneContext& c, const toml::table* out, bool smoke, OutputSettings& o) {
  Reader& r = c.r;
  const int D = c.D;
  // 3D frames show the whole volume by default; a 2D field is its own slice.
  const toml::node* viewNode = r.node(out, "output.", "view");
  o.view = r.string(out, "output.", "view", D == 3 ? "volume" : "slice", {"volume", "slice"});
  if (D == 2 && o.view == "volume")
    r.fail(viewNode, "output.view", "a 2D scene's frames show its field itself; \"volume\" is for 3D scenes",
           "drop output.view, or set it to \"slice\"");
  o.imageSize = int(r.integer(out, "output.", "image_size", 512, 16, 8192));
  // The lit volume's blackbody emission from the smoke's temperature.
  const toml::node* em = r.node(out, "output.", "emission");
  o.emission = r.number(out, "output.", "emission", 0.0, 0.0, 1e3);
  if (em && !(D == 3 && smoke))
    r.fail(em, "output.emission", "it is the glow of a 3D smoke's temperature, and this scene has no 3D [smoke]",
           "drop output.emission");
  o.slice = int(r.integer(out, "output.", "slice", -1, -1, D == 3 ? long(c.res[2]) - 1 : -1));
  // Normal and height maps of the shown field (seed 000 fig. 7).
  const toml::node* nm = r.node(out, "output.", "normal_map");
  o.normalMap = r.boolean(out, "output.", "normal_map", false);
  if (o.normalMap && D == 3)
    r.fail(nm, "output.normal_map", "normal maps are of 2D patterns read as height fields; this scene is 3D",
           "drop output.normal_map, or run the pattern in 2D");
  o.normalStrength = r.number(out, "output.", "normal_strength", 4.0, 0.0, 1e6, true);
}

}  // namespace

void parseOutput(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  toml::table& root = c.root;
  Scene& s = *sp;
  const std::vector<std::string>& species = c.species;
  const toml::table* out = r.table(root, "", "output");
  s.output.every = int(r.integer(out, "output.", "every", 10, 1, 1'000'000'000));
  s.output.images = r.boolean(out, "output.", "images", true);
  s.output.fields = r.boolean(out, "output.", "fields", false);
  s.output.format = r.string(out, "output.", "format", "png", {"png", "exr"});
  s.output.checkpointEvery = int(r.integer(out, "output.", "checkpoint_every", 10, 0, 1'000'000'000));
  s.output.video = r.boolean(out, "output.", "video", false);
  s.output.fps = int(r.integer(out, "output.", "fps", 30, 1, 240));
  if (s.output.video && (!s.output.images || s.output.format != "png"))
    r.fail(r.node(out, "output.", "video"), "output.video",
           "the video is made from PNG frames, so it needs output.images = true and output.format = \"png\"",
           "turn the PNG frames on, or set output.video = false");
  const bool smoke = s.hasFluid && s.fluid.smoke.enabled;
  const std::string byDefault = s.rd.enabled ? species.front() : smoke ? fields::kDye : fields::kVorticity;
  s.output.field = r.string(out, "output.", "field", byDefault, FieldCatalogue(s).outputNames());
  parseVdbOutput(c, out, s);
  parsePalette(c, out, s.output);
  parseView(c, out, s.hasFluid && s.fluid.smoke.enabled, s.output);
}

}  // namespace morphoflow
