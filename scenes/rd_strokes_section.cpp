// [[rd.strokes]]: brush strokes painted on the reaction-diffusion layer (seed
// 001 sec. 6), as polylines in domain units or as an image; each may deposit
// chemical (the cells under it held at `values`).
#include <cmath>
#include <sstream>

#include "scenes/scene_reader.h"

namespace morphoflow {

namespace {

// points = [[x, y], ...]: at least two, each inside the domain.
std::vector<std::array<double, 3>> strokePoints(Reader& r, const toml::node* n, const std::string& key, int D,
                                                const std::vector<double>& size) {
  const toml::array* arr = n->as_array();
  const std::string axes = D == 2 ? "[x, y]" : "[x, y, z]";
  if (!arr) r.fail(n, key, "expected an array of points " + axes + ", found " + describe(*n));
  if (arr->size() < 2)
    r.fail(n, key, "a stroke is a polyline of at least two points, found " + std::to_string(arr->size()),
           "e.g. points = [[0.2, 0.5], [0.8, 0.5]] (domain units)");
  std::vector<std::array<double, 3>> pts;
  for (size_t q = 0; q < arr->size(); ++q) {
    const toml::node* e = arr->get(q);
    const toml::array* pa = e->as_array();
    const std::string full = key + "." + std::to_string(q);
    if (!pa || pa->size() != size_t(D))
      r.fail(e, full, "expected a point " + axes + " of " + std::to_string(D) + " numbers");
    std::array<double, 3> p{0.0, 0.0, 0.0};
    for (int a = 0; a < D; ++a) {
      p[size_t(a)] = r.checkNumber(pa->get(size_t(a)), full, -1e12, 1e12, false);
      if (p[size_t(a)] < 0.0 || p[size_t(a)] > size[size_t(a)]) {
        std::ostringstream m;
        m << "the point is outside the domain: "
          << "xyz"[a] << " = " << p[size_t(a)] << " is not in [0, " << size[size_t(a)] << "]";
        r.fail(e, full, m.str(), "stroke points are in domain units ([domain] size)");
      }
    }
    pts.push_back(p);
  }
  return pts;
}

}  // namespace

void parseStrokes(SceneContext& c, const toml::table& rdt, RDScene* out) {
  Reader& r = c.r;
  const toml::node* sn = r.node(&rdt, "rd.", "strokes");
  if (!sn) return;
  const toml::array* arr = sn->as_array();
  if (!arr || !arr->is_array_of_tables())
    r.fail(sn, "rd.strokes", "expected [[rd.strokes]] tables with points = [[x, y], ...] or image = \"file\"");
  const size_t n = c.species.size();
  for (size_t q = 0; q < arr->size(); ++q) {
    const toml::table* t = arr->get(q)->as_table();
    const std::string p = "rd.strokes." + std::to_string(q) + ".";
    RDStroke s;
    s.where = r.where(t, p + "points");
    s.key = p + "points";
    const toml::node* pts = r.node(t, p, "points");
    const toml::node* img = r.node(t, p, "image");
    if (pts && img)
      r.fail(img, p + "image", "give either points (a polyline) or image (a picture of strokes), not both");
    if (!pts && !img)
      r.fail(t, p + "points", "a stroke needs points = [[x, y], ...] (domain units) or image = \"file\"");
    if (pts) {
      s.stroke.points = strokePoints(r, pts, p + "points", c.D, c.size);
    } else {
      s.where = r.where(img, p + "image");
      s.key = p + "image";
      s.stroke.image = r.field(t, "rd.strokes." + std::to_string(q), c.sceneDir).field;
      bool bright = false;
      for (float v : s.stroke.image.image) bright |= v > 0.5f;
      if (!bright)
        r.fail(img, p + "image", "the image has no stroke: no pixel is brighter than half",
               "strokes are light on dark");
    }
    s.stroke.width = r.number(t, p, "width", 0.0, 0.0, 1e12);
    s.start = r.number(t, p, "start", 0.0, 0.0, 1e12);
    if (const toml::node* sp = r.node(t, p, "species")) {
      s.species = speciesIndices(r, sp, p + "species", c.species, out->settings.model, false);
    } else if (r.node(t, p, "values")) {
      for (size_t k = 0; k < n; ++k) s.species.push_back(int(k));
    }
    if (!s.species.empty()) {
      if (!r.node(t, p, "values"))
        r.fail(t, p + "values", "a stroke that deposits species needs values, one per species",
               "species: " + join(c.species));
      s.values = r.numbers(t, p, "values", {}, s.species.size(), s.species.size(), -1e12, 1e12);
    }
    out->strokes.push_back(std::move(s));
  }
}

}  // namespace morphoflow
