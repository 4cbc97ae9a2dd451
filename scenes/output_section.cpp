// [output]: frames (field, palette, range, format), field dumps and video.
#include "scenes/scene_reader.h"

#include "render/colormap.h"

namespace morphoflow {

void parseOutput(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  toml::table& root = c.root;
  Scene& s = *sp;
  const int D = c.D;
  const std::vector<double>& res = c.res;
  const std::vector<std::string>& species = c.species;
  const toml::table* out = r.table(root, "", "output");
  s.output.every = int(r.integer(out, "output.", "every", 10, 1, 1'000'000'000));
  s.output.images = r.boolean(out, "output.", "images", true);
  s.output.fields = r.boolean(out, "output.", "fields", false);
  s.output.format = r.string(out, "output.", "format", "png", {"png", "exr"});
  if (r.boolean(out, "output.", "vdb", false))
    r.fail(r.node(out, "output.", "vdb"), "output.vdb", "this build of morphoflow does not write vdb yet",
           "set it to false");
  s.output.checkpointEvery = int(r.integer(out, "output.", "checkpoint_every", 10, 0, 1'000'000'000));
  s.output.video = r.boolean(out, "output.", "video", false);
  s.output.fps = int(r.integer(out, "output.", "fps", 30, 1, 240));
  if (s.output.video && (!s.output.images || s.output.format != "png"))
    r.fail(r.node(out, "output.", "video"), "output.video",
           "the video is made from PNG frames, so it needs output.images = true and output.format = \"png\"",
           "turn the PNG frames on, or set output.video = false");
  if (s.rd.enabled && s.hasFluid) {
    std::vector<std::string> choices = species;
    for (const char* f : {"speed", "vorticity", "dye", "pressure"}) choices.push_back(f);
    s.output.field = r.string(out, "output.", "field", species.front(), choices);
  } else if (s.rd.enabled)
    s.output.field = r.string(out, "output.", "field", species.front(), species);
  else
    s.output.field = r.string(out, "output.", "field", "vorticity", {"speed", "vorticity", "dye", "pressure"});
  s.output.colormap = r.string(out, "output.", "colormap", s.output.field == "vorticity" ? "coolwarm" : "viridis",
                               colormapNames());
  if (s.output.colormap == kTwoSpeciesPalette && species.size() < 2)
    r.fail(r.node(out, "output.", "colormap"), "output.colormap",
           std::string(kTwoSpeciesPalette) + " shows two reaction-diffusion species (the first in red, the second in green)",
           "use it with an [rd] model of two or more species, or pick a scalar palette");
  if (const toml::node* g = r.node(out, "output.", "gradient")) {
    const toml::array* arr = g->as_array();
    if (!arr || arr->size() < 2)
      r.fail(g, "output.gradient", "expected an array of two or more colours, e.g. [\"#000000\", \"#ff8800\", \"#ffffff\"]");
    for (const toml::node& e : *arr) {
      Rgb8 c;
      auto text = e.value<std::string>();
      if (!text || !parseHexColour(*text, &c))
        r.fail(&e, "output.gradient", "expected a colour as \"#rrggbb\"", "e.g. \"#ff8800\" for orange");
      s.output.gradient.push_back(c);
    }
  }
  const toml::node* rangeNode = nullptr;
  std::vector<double> range = r.numbers(out, "output.", "range", {}, 2, 2, -1e30, 1e30, false, &rangeNode);
  if (!range.empty()) {
    if (!(range[0] < range[1])) r.fail(rangeNode, "output.range", "expected [low, high] with low < high");
    s.output.autoRange = false;
    s.output.range[0] = range[0];
    s.output.range[1] = range[1];
  }
  s.output.slice = int(r.integer(out, "output.", "slice", -1, -1, D == 3 ? long(res[2]) - 1 : -1));
}

}  // namespace morphoflow
