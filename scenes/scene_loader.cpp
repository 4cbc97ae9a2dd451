#include "scenes/scene_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include "render/image_io.h"
#include "render/colormap.h"
#include "rd/model_registry.h"

namespace morphoflow {

int editDistance(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = int(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = int(i);
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

namespace {

std::string join(const std::vector<std::string>& v, const std::string& sep = ", ") {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

std::string nearest(const std::string& word, const std::vector<std::string>& choices) {
  std::string best;
  int bestD = 1 << 30;
  for (const auto& c : choices) {
    int d = editDistance(word, c);
    if (d < bestD) {
      bestD = d;
      best = c;
    }
  }
  return best;
}

std::string describe(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

// Reads typed values out of the TOML tree, remembering which keys each table
// was asked for, so that whatever is left over is an unknown key.
class Reader {
 public:
  Reader(std::string file, toml::table& root, std::map<std::string, SourceLocation> overrideLocs)
      : file_(std::move(file)), root_(root), overrideLocs_(std::move(overrideLocs)) {}

  SourceLocation where(const toml::node* n, const std::string& key) const {
    auto it = overrideLocs_.find(key);
    if (it != overrideLocs_.end()) return it->second;
    if (!n) return {file_, 0, 0};
    return {file_, int(n->source().begin.line), int(n->source().begin.column)};
  }
  [[noreturn]] void fail(const toml::node* n, const std::string& key, const std::string& msg,
                         const std::string& hint = {}) const {
    throw UserError(where(n, key), key, msg, hint);
  }

  // The sub-table `name` of `parent` (null when absent).
  const toml::table* table(const toml::table& parent, const std::string& prefix, const std::string& name) {
    known_[&parent].insert(name);
    const toml::node* n = parent.get(name);
    if (!n) return nullptr;
    if (!n->is_table()) fail(n, prefix + name, "expected a table ([" + prefix + name + "]), found " + describe(*n));
    return n->as_table();
  }
  const toml::node* node(const toml::table* t, const std::string& prefix, const std::string& key) {
    if (!t) return nullptr;
    known_[t].insert(key);
    return t->get(key);
  }

  double number(const toml::table* t, const std::string& prefix, const std::string& key, double def,
                double lo, double hi, bool loOpen = false) {
    const toml::node* n = node(t, prefix, key);
    if (!n) return def;
    return checkNumber(n, prefix + key, lo, hi, loOpen);
  }
  double checkNumber(const toml::node* n, const std::string& full, double lo, double hi, bool loOpen) {
    if (!n->is_number()) fail(n, full, "expected a number, found " + describe(*n));
    double v = n->value<double>().value();
    if (!std::isfinite(v)) fail(n, full, "expected a finite number");
    if (v < lo || (loOpen && v == lo) || v > hi) {
      std::ostringstream r;
      r << "expected a number in " << (loOpen ? "(" : "[") << lo << ", " << hi << "], found " << v;
      fail(n, full, r.str());
    }
    return v;
  }
  long integer(const toml::table* t, const std::string& prefix, const std::string& key, long def, long lo,
               long hi) {
    const toml::node* n = node(t, prefix, key);
    if (!n) return def;
    if (!n->is_integer()) fail(n, prefix + key, "expected an integer, found " + describe(*n));
    long v = long(n->value<int64_t>().value());
    if (v < lo || v > hi)
      fail(n, prefix + key,
           "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], found " +
               std::to_string(v));
    return v;
  }
  bool boolean(const toml::table* t, const std::string& prefix, const std::string& key, bool def) {
    const toml::node* n = node(t, prefix, key);
    if (!n) return def;
    if (!n->is_boolean()) fail(n, prefix + key, "expected true or false, found " + describe(*n));
    return n->value<bool>().value();
  }
  std::string string(const toml::table* t, const std::string& prefix, const std::string& key,
                     const std::string& def, const std::vector<std::string>& choices = {}) {
    const toml::node* n = node(t, prefix, key);
    if (!n) return def;
    if (!n->is_string()) fail(n, prefix + key, "expected a string, found " + describe(*n));
    std::string v = n->value<std::string>().value();
    if (!choices.empty() && std::find(choices.begin(), choices.end(), v) == choices.end())
      fail(n, prefix + key, "'" + v + "' is not one of: " + join(choices),
           "did you mean '" + nearest(v, choices) + "'?");
    return v;
  }
  // An array of numbers of length in [minLen, maxLen].
  std::vector<double> numbers(const toml::table* t, const std::string& prefix, const std::string& key,
                              std::vector<double> def, size_t minLen, size_t maxLen, double lo, double hi,
                              bool loOpen = false, const toml::node** out = nullptr) {
    const toml::node* n = node(t, prefix, key);
    if (out) *out = n;
    if (!n) return def;
    const std::string full = prefix + key;
    const toml::array* arr = n->as_array();
    if (!arr) fail(n, full, "expected an array of numbers, found " + describe(*n));
    if (arr->size() < minLen || arr->size() > maxLen)
      fail(n, full,
           "expected " + (minLen == maxLen ? std::to_string(minLen) : std::to_string(minLen) + " or " + std::to_string(maxLen)) +
               " numbers, found " + std::to_string(arr->size()));
    std::vector<double> v;
    for (const toml::node& e : *arr) v.push_back(checkNumber(&e, full, lo, hi, loOpen));
    return v;
  }

  // Every key nobody asked for is an error; the nearest asked-for key is suggested.
  void checkUnknown(const toml::table& t, const std::string& prefix) {
    std::vector<std::string> valid(known_[&t].begin(), known_[&t].end());
    for (auto&& [k, v] : t) {
      std::string key(k.str());
      if (!known_[&t].count(key)) {
        std::string hint = valid.empty() ? "" : "did you mean '" + prefix + nearest(key, valid) + "'?";
        fail(&v, prefix + key, "unknown key", hint + (valid.empty() ? "" : " valid keys here: " + join(valid)));
      }
      if (v.is_table()) checkUnknown(*v.as_table(), prefix + key + ".");
      if (v.is_array_of_tables()) {
        const toml::array& a = *v.as_array();
        for (size_t i = 0; i < a.size(); ++i)
          if (known_.count(a.get(i)->as_table()))
            checkUnknown(*a.get(i)->as_table(), prefix + key + "." + std::to_string(i) + ".");
      }
    }
  }

  // A spatial field: an expression string, or { image = "file", range = [lo, hi] }.
  SceneField field(const toml::node* n, const std::string& full, const std::filesystem::path& sceneDir) {
    SceneField f;
    f.where = where(n, full);
    f.key = full;
    if (n->is_string() || n->is_number()) {
      f.field.expression = n->is_string() ? n->value<std::string>().value() : std::to_string(n->value<double>().value());
      try {
        compileSpatialField(f.field.expression);
      } catch (const ExpressionError& e) {
        SourceLocation at = f.where;
        if (at.line > 0 && n->is_string()) at.column += 1 + int(e.column());
        throw UserError(at, full, std::string("in the expression: ") + e.what(),
                        "see docs/scenes.md, Spatial fields");
      }
      return f;
    }
    const toml::table* t = n->as_table();
    if (!t)
      fail(n, full, "expected an expression string or a table { image = \"file\", range = [low, high] }, found " + describe(*n));
    const toml::node* img = node(t, full + ".", "image");
    if (!img) fail(n, full, "an image field needs image = \"path\"");
    std::string file = string(t, full + ".", "image", "");
    std::filesystem::path fp = std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : sceneDir / file;
    GrayImage g;
    std::string err;
    if (!readGrayImage(fp.string(), &g, &err)) fail(img, full + ".image", "cannot read the image: " + err);
    f.field.imageWidth = g.width;
    f.field.imageHeight = g.height;
    f.field.image = std::move(g.pixels);
    std::vector<double> range = numbers(t, full + ".", "range", {0.0, 1.0}, 2, 2, -1e12, 1e12);
    f.field.range[0] = range[0];
    f.field.range[1] = range[1];
    return f;
  }

  const std::string& file() const { return file_; }
  toml::table& root() { return root_; }

 private:
  std::string file_;
  toml::table& root_;
  std::map<std::string, SourceLocation> overrideLocs_;
  std::map<const toml::table*, std::set<std::string>> known_;
};

// Applies one --set key.path=value override; value is TOML.
void applyOverride(toml::table& root, const std::string& kv, std::map<std::string, SourceLocation>* locs) {
  const std::string origin = "--set " + kv;
  size_t eq = kv.find('=');
  if (eq == std::string::npos || eq == 0)
    throw UserError({origin, 1, 1}, "", "expected key.path=value", "e.g. --set fluid.reynolds=400");
  std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value, origin);
  } catch (const toml::parse_error& e) {
    throw UserError({origin, 1, int(eq) + 2}, key, "the value is not valid TOML: " + std::string(e.description()),
                    "strings need quotes: --set 'rd.model=\"gray-scott\"'");
  }
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  toml::node* cur = &root;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    if (toml::array* a = cur->as_array()) {
      size_t idx = 0;
      try {
        idx = std::stoul(parts[i]);
      } catch (...) {
        throw UserError({origin, 1, 1}, key, "'" + parts[i] + "' should be an index into an array");
      }
      if (idx >= a->size())
        throw UserError({origin, 1, 1}, key, "index " + parts[i] + " is past the end of the array");
      cur = a->get(idx);
      continue;
    }
    toml::table* t = cur->as_table();
    if (!t) throw UserError({origin, 1, 1}, key, "'" + parts[i] + "' is not a table");
    if (!t->contains(parts[i])) t->insert(parts[i], toml::table{});
    cur = t->get(parts[i]);
  }
  toml::table* t = cur->as_table();
  if (!t) throw UserError({origin, 1, 1}, key, "the parent of '" + parts.back() + "' is not a table");
  parsed.get("v")->visit([&](auto&& n) { t->insert_or_assign(parts.back(), n); });
  (*locs)[key] = {origin, 1, int(eq) + 2};
}

ObstacleShape parseShape(const std::string& s) {
  if (s == "circle") return ObstacleShape::Circle;
  if (s == "sphere") return ObstacleShape::Sphere;
  if (s == "box") return ObstacleShape::Box;
  if (s == "image") return ObstacleShape::Image;
  return ObstacleShape::Sdf;
}

BoundaryKind parseBoundary(const std::string& s) {
  if (s == "inflow") return BoundaryKind::Inflow;
  if (s == "outflow") return BoundaryKind::Outflow;
  if (s == "periodic") return BoundaryKind::Periodic;
  return BoundaryKind::Wall;
}

}  // namespace

long Scene::totalSteps() const {
  if (time.steps > 0) return time.steps;
  return long(std::ceil(time.duration / time.dt - 1e-9));
}

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  toml::table root;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UserError({path, 0, 0}, "", "cannot open the scene file", "check the path");
    std::stringstream buf;
    buf << in.rdbuf();
    try {
      root = toml::parse(buf.str(), path);
    } catch (const toml::parse_error& e) {
      throw UserError({path, int(e.source().begin.line), int(e.source().begin.column)}, "",
                      "not valid TOML: " + std::string(e.description()));
    }
  }
  std::map<std::string, SourceLocation> overrideLocs;
  for (const std::string& kv : overrides) applyOverride(root, kv, &overrideLocs);

  Reader r(path, root, overrideLocs);
  Scene s;
  s.path = path;
  s.name = std::filesystem::path(path).stem().string();
  const std::filesystem::path sceneDir = std::filesystem::path(path).parent_path();
  const toml::table* top = &root;
  s.name = r.string(top, "", "name", s.name);
  s.seed = uint64_t(r.integer(top, "", "seed", 1, 0, (1L << 62)));

  // [grid] and [domain]
  const toml::table* grid = r.table(root, "", "grid");
  const toml::node* resNode = nullptr;
  std::vector<double> res = r.numbers(grid, "grid.", "resolution", {128, 128}, 2, 3, 4, 8192, false, &resNode);
  for (double v : res)
    if (v != std::floor(v)) r.fail(resNode, "grid.resolution", "cell counts must be whole numbers");
  s.dimension = int(res.size());
  const int D = s.dimension;
  double cells = 1;
  for (double v : res) cells *= v;
  if (cells > double(1 << 28))
    r.fail(resNode, "grid.resolution", "the grid has too many cells for this machine's memory",
           "at most 268435456 cells");
  // Reaction-diffusion-only scenes default to unit cells (the seeds' units);
  // fluid scenes to a unit-wide box.
  const bool rdOnly = root.contains("rd") && !root.contains("fluid");
  std::vector<double> defSize;
  for (double v : res) defSize.push_back(rdOnly ? v : v / res[0]);
  const toml::table* domain = r.table(root, "", "domain");
  const toml::node* sizeNode = nullptr;
  std::vector<double> size = r.numbers(domain, "domain.", "size", defSize, size_t(D), size_t(D), 0, 1e9, true, &sizeNode);
  const double h = size[0] / res[0];
  for (int a = 1; a < D; ++a)
    if (std::abs(size[size_t(a)] / res[size_t(a)] - h) > 1e-6 * h) {
      std::ostringstream hint;
      hint << "cells must be square: use domain.size = [";
      for (int b = 0; b < D; ++b) hint << (b ? ", " : "") << h * res[size_t(b)];
      hint << "] or change grid.resolution";
      r.fail(sizeNode ? sizeNode : resNode, "domain.size", "size / resolution differs between axes", hint.str());
    }
  s.fluid.resolution.clear();
  for (double v : res) s.fluid.resolution.push_back(int(v));
  s.fluid.size = size;

  // [time]
  const toml::table* time = r.table(root, "", "time");
  s.time.dt = r.number(time, "time.", "dt", 0.01, 0, 1e6, true);
  const toml::node* stepsNode = r.node(time, "time.", "steps");
  const toml::node* durNode = r.node(time, "time.", "duration");
  if (stepsNode && durNode) r.fail(durNode, "time.duration", "give either time.steps or time.duration, not both");
  s.time.steps = r.integer(time, "time.", "steps", 0, 1, 100'000'000);
  s.time.duration = r.number(time, "time.", "duration", 0.0, 0, 1e9, true);
  if (!stepsNode && !durNode) s.time.steps = 100;
  s.time.cfl = r.number(time, "time.", "cfl", 0.0, 0, 1000);

  // [boundary]
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

  // [[obstacles]]
  r.node(top, "", "obstacles");
  if (const toml::node* obs = root.get("obstacles")) {
    const toml::array* arr = obs->as_array();
    if (!arr || !arr->is_array_of_tables())
      r.fail(obs, "obstacles", "expected an array of tables ([[obstacles]])");
    for (size_t i = 0; i < arr->size(); ++i) {
      const toml::table* o = arr->get(i)->as_table();
      const std::string p = "obstacles." + std::to_string(i) + ".";
      ObstacleSpec spec;
      std::string shape = r.string(o, p, "shape", "circle", {"circle", "sphere", "box", "image", "sdf"});
      spec.shape = parseShape(shape);
      std::vector<double> centre(static_cast<size_t>(D), 0.0);
      for (int a = 0; a < D; ++a) centre[size_t(a)] = 0.5 * size[size_t(a)];
      const toml::node* cn = nullptr;
      centre = r.numbers(o, p, "center", centre, size_t(D), size_t(D), -1e9, 1e9, false, &cn);
      for (int a = 0; a < D; ++a) {
        if (centre[size_t(a)] < 0 || centre[size_t(a)] > size[size_t(a)])
          r.fail(cn, p + "center", "the centre lies outside the domain", "domain.size is " + std::to_string(size[size_t(a)]) + " along axis " + std::to_string(a));
        spec.center[size_t(a)] = centre[size_t(a)];
      }
      if (spec.shape == ObstacleShape::Circle || spec.shape == ObstacleShape::Sphere) {
        if (!r.node(o, p, "radius")) r.fail(o, p + "radius", "a " + shape + " needs a radius");
        spec.radius = r.number(o, p, "radius", 0.1, 0, 1e9, true);
      } else if (spec.shape == ObstacleShape::Box) {
        if (!r.node(o, p, "size")) r.fail(o, p + "size", "a box needs a size = [..] (its full extent)");
        std::vector<double> sz = r.numbers(o, p, "size", {}, size_t(D), size_t(D), 0, 1e9, true);
        for (int a = 0; a < D; ++a) spec.halfSize[size_t(a)] = 0.5 * sz[size_t(a)];
      } else {
        const std::string key = "file";
        const toml::node* fn = r.node(o, p, key);
        if (!fn) r.fail(o, p + key, "an " + shape + " obstacle needs file = \"path\"");
        std::string file = r.string(o, p, key, "");
        std::filesystem::path fp = std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : sceneDir / file;
        GrayImage img;
        std::string err;
        if (!readGrayImage(fp.string(), &img, &err)) r.fail(fn, p + key, "cannot read the image: " + err);
        spec.fieldWidth = img.width;
        spec.fieldHeight = img.height;
        spec.field = std::move(img.pixels);
        spec.threshold = r.number(o, p, "threshold", 0.5, -1e9, 1e9);
        spec.invert = r.boolean(o, p, "invert", false);
      }
      s.fluid.obstacles.push_back(spec);
    }
  }

  // [fluid]
  const toml::table* fluid = r.table(root, "", "fluid");
  s.fluid.density = r.number(fluid, "fluid.", "density", 1.0, 0, 1e9, true);
  double lid = r.number(fluid, "fluid.", "lid_velocity", 0.0, -1e6, 1e6);
  if (lid != 0.0) {
    if (s.fluid.boundaries.sides[3].kind != BoundaryKind::Wall)
      r.fail(r.node(fluid, "fluid.", "lid_velocity"), "fluid.lid_velocity", "the lid is the y_max side, which must be a wall");
    s.fluid.boundaries.sides[3].wallVelocity = {lid, 0.0, 0.0};
  }
  // Reference scales: obstacle diameter and mean inflow, else the lid.
  ProbeSettings& pr = s.probes;
  pr.referenceLength = size[0];
  pr.referenceSpeed = lid != 0.0 ? std::abs(lid) : 1.0;
  pr.referenceArea = D == 2 ? size[0] : size[0] * size[2];
  if (inflowSide >= 0) pr.referenceSpeed = std::abs(s.fluid.boundaries.inflowMeanVelocity);
  if (inflowSide >= 0 && !s.fluid.obstacles.empty()) {
    const ObstacleSpec& o = s.fluid.obstacles.front();
    int flow = inflowSide / 2, across = flow == 1 ? 0 : 1;
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
  const toml::node* reNode = r.node(fluid, "fluid.", "reynolds");
  const toml::node* nuNode = r.node(fluid, "fluid.", "viscosity");
  if (reNode && nuNode && overrideLocs.count("fluid.reynolds") == overrideLocs.count("fluid.viscosity"))
    r.fail(reNode, "fluid.reynolds", "give either fluid.reynolds or fluid.viscosity, not both");
  bool useRe = reNode && !(nuNode && overrideLocs.count("fluid.viscosity"));
  if (useRe) {
    s.reynolds = r.number(fluid, "fluid.", "reynolds", 100.0, 0, 1e12, true);
    s.fluid.viscosity = pr.referenceSpeed * pr.referenceLength / s.reynolds;
  } else {
    s.fluid.viscosity = r.number(fluid, "fluid.", "viscosity", 1e-3, 0, 1e9);
    s.reynolds = s.fluid.viscosity > 0 ? pr.referenceSpeed * pr.referenceLength / s.fluid.viscosity : 0.0;
  }
  std::string adv = r.string(fluid, "fluid.", "advection", "maccormack", {"semi-lagrangian", "maccormack", "bfecc"});
  s.fluid.advection = adv == "semi-lagrangian" ? AdvectionScheme::SemiLagrangian
                      : adv == "bfecc"         ? AdvectionScheme::Bfecc
                                               : AdvectionScheme::MacCormack;
  std::string ps = r.string(fluid, "fluid.", "pressure_solver", "mgpcg", {"mgpcg", "icpcg", "multigrid"});
  s.fluid.pressureSolver = ps == "icpcg" ? PressureSolver::ICPCG : ps == "multigrid" ? PressureSolver::Multigrid : PressureSolver::MGPCG;
  s.fluid.pressureTolerance = r.number(fluid, "fluid.", "pressure_tolerance", 1e-6, 0, 1, true);
  s.fluid.pressureMaxIterations = int(r.integer(fluid, "fluid.", "pressure_max_iterations", 500, 1, 100000));
  std::vector<double> force = r.numbers(fluid, "fluid.", "force", std::vector<double>(size_t(D), 0.0), size_t(D), size_t(D), -1e9, 1e9);
  for (int a = 0; a < D; ++a) s.fluid.force[size_t(a)] = force[size_t(a)];
  s.fluid.buoyancy = r.number(fluid, "fluid.", "buoyancy", 0.0, -1e9, 1e9);
  std::vector<double> up(size_t(D), 0.0);
  up[1] = 1.0;
  up = r.numbers(fluid, "fluid.", "buoyancy_direction", up, size_t(D), size_t(D), -1e9, 1e9);
  for (int a = 0; a < D; ++a) s.fluid.buoyancyDirection[size_t(a)] = up[size_t(a)];

  // [dye]
  const toml::table* dye = r.table(root, "", "dye");
  s.dye.initial = r.string(dye, "dye.", "initial", "none", {"none", "stripes", "checker"});
  s.dye.stripes = int(r.integer(dye, "dye.", "stripes", 8, 1, 4096));

  // [probes]
  const toml::table* probes = r.table(root, "", "probes");
  pr.centerlines = r.boolean(probes, "probes.", "centerlines", false);
  pr.forces = r.boolean(probes, "probes.", "forces", false);
  if (pr.forces && s.fluid.obstacles.empty())
    r.fail(r.node(probes, "probes.", "forces"), "probes.forces", "there is no obstacle to measure forces on");
  pr.strouhalStart = r.number(probes, "probes.", "strouhal_start", -1.0, -1.0, 1e12);

  // [rd]
  std::vector<std::string> species;
  if (const toml::table* rdt = r.table(root, "", "rd")) {
    s.hasFluid = !rdOnly;
    RDScene& R = s.rd;
    R.enabled = true;
    const std::vector<std::string> names = modelNames();
    if (!r.node(rdt, "rd.", "model")) r.fail(rdt, "rd.model", "a reaction-diffusion scene needs rd.model", "models: " + join(names));
    const std::string model = r.string(rdt, "rd.", "model", "", names);
    const ModelInfo& in = findModel(model)->info();
    const size_t n = in.species.size();
    species = in.species;
    RDSettings& st = R.settings;
    st.model = model;
    st.resolution.clear();
    for (double v : res) st.resolution.push_back(int(v));
    st.size = size;
    if (!rdOnly) {
      // A coupled layer spans the fluid's domain, on its own grid if asked.
      const toml::node* rn = nullptr;
      std::vector<double> rr = r.numbers(rdt, "rd.", "resolution", res, size_t(D), size_t(D), 4, 8192, false, &rn);
      st.resolution.clear();
      for (int a = 0; a < D; ++a) {
        st.resolution.push_back(int(rr[size_t(a)]));
        if (std::abs(size[size_t(a)] / rr[size_t(a)] - size[0] / rr[0]) > 1e-6 * size[0] / rr[0])
          r.fail(rn, "rd.resolution", "reaction-diffusion cells must be square over the domain",
                 "keep rd.resolution proportional to grid.resolution");
      }
    }
    st.diffusion = r.numbers(rdt, "rd.", "diffusion", in.diffusion, n, n, 0, 1e12);
    const std::string integ = r.string(rdt, "rd.", "integrator", "kim-lin", {"kim-lin", "explicit", "semi-implicit", "crank-nicolson"});
    st.integrator = integ == "explicit"        ? RDIntegrator::ExplicitEuler
                    : integ == "semi-implicit" ? RDIntegrator::SemiImplicit
                    : integ == "crank-nicolson" ? RDIntegrator::CrankNicolson
                                               : RDIntegrator::KimLin;
    // A coupled layer's boundary follows the fluid's: periodic where it wraps, zero flux at walls.
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
    st.boundary = bc == "neumann" ? RDBoundary::Neumann : bc == "dirichlet" ? RDBoundary::Dirichlet : RDBoundary::Periodic;
    st.dirichletValues = r.numbers(rdt, "rd.", "boundary_values", {}, n, n, -1e12, 1e12);
    if (st.boundary == RDBoundary::Dirichlet && st.dirichletValues.empty())
      r.fail(r.node(rdt, "rd.", "boundary"), "rd.boundary_values", "Dirichlet boundaries need boundary_values, one per species",
             "species: " + join(species));
    st.lookupTable = r.boolean(rdt, "rd.", "lookup_table", false);
    st.lookupSize = int(r.integer(rdt, "rd.", "lookup_size", 256, 2, 4096));
    const std::string ls = r.string(rdt, "rd.", "linear_solver", "mgpcg", {"mgpcg", "icpcg"});
    st.linearSolver = ls == "icpcg" ? RDLinearSolver::ICPCG : RDLinearSolver::MGPCG;
    st.tolerance = r.number(rdt, "rd.", "tolerance", 1e-8, 0, 1, true);
    // An array of species names, as indices (rd.frozen, fixed regions, anisotropy).
    auto speciesList = [&](const toml::node* sp, const std::string& key, bool allowEmpty) {
      std::vector<int> out;
      const toml::array* sa = sp->as_array();
      if (!sa || (sa->empty() && !allowEmpty))
        r.fail(sp, key, "expected an array of species names", "species: " + join(species));
      for (const toml::node& e : *sa) {
        auto v = e.value<std::string>();
        auto f = v ? std::find(species.begin(), species.end(), *v) : species.end();
        if (f == species.end()) r.fail(&e, key, "expected species names of " + model + ": " + join(species));
        out.push_back(int(f - species.begin()));
      }
      return out;
    };
    if (const toml::node* fr = r.node(rdt, "rd.", "frozen")) st.frozen = speciesList(fr, "rd.frozen", true);
    // [rd.parameters]: uniform values by name.
    const toml::table* pt = r.table(*rdt, "rd.", "parameters");
    for (const ParameterInfo& p : in.parameters)
      st.parameters.push_back(r.number(pt, "rd.parameters.", p.name, p.value, -1e12, 1e12));
    // [rd.initial]
    const toml::table* it = r.table(*rdt, "rd.", "initial");
    RDInitial& I = R.initial;
    I.values = r.numbers(it, "rd.initial.", "values", in.initial, n, n, -1e12, 1e12);
    if (const toml::node* nz = r.node(it, "rd.initial.", "noise"); nz && nz->is_number())
      I.noise.assign(n, r.number(it, "rd.initial.", "noise", 0.0, 0, 1e12));
    else
      I.noise = r.numbers(it, "rd.initial.", "noise", std::vector<double>(n, 0.0), n, n, 0, 1e12);
    const toml::node* rn = nullptr;
    std::vector<double> range = r.numbers(it, "rd.initial.", "random_range", {}, 2, 2, -1e12, 1e12, false, &rn);
    if (!range.empty()) {
      if (!(range[0] < range[1])) r.fail(rn, "rd.initial.random_range", "expected [low, high] with low < high");
      I.randomRange = true;
      I.range[0] = range[0];
      I.range[1] = range[1];
    }
    I.square = r.number(it, "rd.initial.", "square", 0.0, 0, 1);
    I.squareValues = r.numbers(it, "rd.initial.", "square_values", {}, n, n, -1e12, 1e12);
    if (I.square > 0 && I.squareValues.empty())
      r.fail(r.node(it, "rd.initial.", "square"), "rd.initial.square_values", "a central square needs square_values, one per species",
             "species: " + join(species));
    // [rd.initial.maps]: species -> spatial field, replacing its uniform value.
    if (const toml::table* im = it ? r.table(*it, "rd.initial.", "maps") : nullptr) {
      for (auto&& [k, v] : *im) {
        const std::string name(k.str());
        auto sp = std::find(species.begin(), species.end(), name);
        if (sp == species.end())
          r.fail(&v, "rd.initial.maps." + name, "not a species of " + model, "species: " + join(species));
        r.node(im, "rd.initial.maps.", name);
        R.initialMaps.push_back({int(sp - species.begin()), r.field(&v, "rd.initial.maps." + name, sceneDir)});
      }
    }
    // [rd.maps]: parameter -> spatial field (gradients, radial/angular functions, images).
    std::vector<std::string> pnames;
    for (const ParameterInfo& p : in.parameters) pnames.push_back(p.name);
    if (const toml::table* mp = r.table(*rdt, "rd.", "maps")) {
      for (auto&& [k, v] : *mp) {
        const std::string name(k.str());
        auto pi = std::find(pnames.begin(), pnames.end(), name);
        if (pi == pnames.end())
          r.fail(&v, "rd.maps." + name, "not a parameter of " + model,
                 "did you mean '" + nearest(name, pnames) + "'? parameters: " + join(pnames));
        r.node(mp, "rd.maps.", name);
        R.parameterMaps.push_back({int(pi - pnames.begin()), r.field(&v, "rd.maps." + name, sceneDir)});
      }
    }
    // [[rd.fixed]]: regions held at fixed values (seed 004 fig. 20).
    r.node(rdt, "rd.", "fixed");
    if (const toml::node* fx = rdt->get("fixed")) {
      const toml::array* arr = fx->as_array();
      if (!arr || !arr->is_array_of_tables())
        r.fail(fx, "rd.fixed", "expected [[rd.fixed]] tables with where = \"expression\" and values = [...]");
      for (size_t q = 0; q < arr->size(); ++q) {
        const toml::table* t = arr->get(q)->as_table();
        const std::string p = "rd.fixed." + std::to_string(q) + ".";
        const toml::node* w = r.node(t, p, "where");
        if (!w) r.fail(t, p + "where", "a fixed region needs where = \"expression\" (nonzero inside), e.g. \"j == 0\"");
        RDFixedRegion fr;
        fr.where = r.field(w, p + "where", sceneDir);
        if (const toml::node* sp = r.node(t, p, "species")) {
          fr.species = speciesList(sp, p + "species", false);
        } else {
          for (size_t q = 0; q < n; ++q) fr.species.push_back(int(q));
        }
        const size_t held = fr.species.size();
        if (!r.node(t, p, "values"))
          r.fail(t, p + "values", "a fixed region needs values, one per held species", "species: " + join(species));
        fr.values = r.numbers(t, p, "values", {}, held, held, -1e12, 1e12);
        R.fixed.push_back(std::move(fr));
      }
    }
    // [rd.anisotropy]: inhomogeneous anisotropic tensor diffusion (seed 004 eq. 11-19).
    if (const toml::table* an = r.table(*rdt, "rd.", "anisotropy")) {
      RDAnisotropy& A = R.anisotropy;
      A.enabled = true;
      const std::string p = "rd.anisotropy.";
      auto fieldOr = [&](const char* key, const char* def) {
        if (const toml::node* f = r.node(an, p, key)) return r.field(f, p + key, sceneDir);
        SceneField d;
        d.field.expression = def;
        d.where = r.where(an, p + key);
        d.key = p + key;
        return d;
      };
      A.lambda1 = fieldOr("lambda1", "1");
      A.lambda2 = fieldOr("lambda2", "1");
      const toml::node* th = r.node(an, p, "theta");
      if (const toml::node* dn = r.node(an, p, "direction")) {
        if (th)
          r.fail(th, p + "theta", "give either theta (an angle in the xy plane) or direction (a vector field), not both",
                 "drop one of them");
        const toml::array* arr = dn->as_array();
        if (!arr || arr->size() != size_t(D))
          r.fail(dn, p + "direction",
                 "expected an array of " + std::to_string(D) + " fields (one per axis), e.g. [\"y - 0.5\", \"x - 0.5\"]");
        for (size_t q = 0; q < arr->size(); ++q)
          A.direction.push_back(r.field(arr->get(q), p + "direction." + std::to_string(q), sceneDir));
      } else {
        A.theta = fieldOr("theta", "0");
      }
      if (const toml::node* sp = r.node(an, p, "species")) A.species = speciesList(sp, p + "species", false);
      A.shape = r.number(an, p, "shape", 0.0, -1e6, 1e6);
      const std::string ss = r.string(an, p, "shape_species", species.front(), species);
      A.shapeSpecies = int(std::find(species.begin(), species.end(), ss) - species.begin());
    }
    // [rd.cosine_lobes]: Kim & Lin's anisotropy function a(theta) (seed 001 eq. 14-17).
    if (const toml::table* cl = r.table(*rdt, "rd.", "cosine_lobes")) {
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
      if (const toml::node* th = r.node(cl, p, "theta0")) {
        L.theta0 = r.field(th, p + "theta0", sceneDir);
      } else {
        L.theta0.field.expression = "0";
        L.theta0.where = r.where(cl, p + "theta0");
        L.theta0.key = p + "theta0";
      }
      if (const toml::node* sp = r.node(cl, p, "species")) L.species = speciesList(sp, p + "species", false);
    }
    // [rd.coarse_to_fine]: grow the pattern on coarser grids first.
    if (const toml::table* cf = r.table(*rdt, "rd.", "coarse_to_fine")) {
      if (!rdOnly)
        r.fail(cf, "rd.coarse_to_fine", "coarse-to-fine growth is for reaction-diffusion-only scenes",
               "drop [rd.coarse_to_fine] from a scene with [fluid]");
      const toml::node* lv = r.node(cf, "rd.coarse_to_fine.", "levels");
      R.coarseLevels = int(r.integer(cf, "rd.coarse_to_fine.", "levels", 2, 1, 8));
      R.coarseSteps = r.integer(cf, "rd.coarse_to_fine.", "steps", 1000, 0, 1'000'000'000);
      R.coarseScaleDt = r.boolean(cf, "rd.coarse_to_fine.", "scale_dt", st.integrator == RDIntegrator::ExplicitEuler);
      for (double v : res) {
        const long cells = long(v);
        if (cells % (1L << R.coarseLevels) != 0 || (cells >> R.coarseLevels) < 4)
          r.fail(lv ? lv : cf, "rd.coarse_to_fine.levels",
                 "each coarser grid halves the resolution, so every grid.resolution entry must be divisible by 2^levels "
                 "and leave at least 4 cells",
                 "use fewer levels or a resolution such as 256");
      }
    }
    // [rd.perturb]: Gaussian perturbation of parameters, sigma in percent.
    const toml::table* pp = r.table(*rdt, "rd.", "perturb");
    for (size_t k = 0; k < in.parameters.size(); ++k)
      if (r.node(pp, "rd.perturb.", in.parameters[k].name))
        R.perturb.push_back({int(k), r.number(pp, "rd.perturb.", in.parameters[k].name, 0.0, 0, 100)});
  }

  // [coupling]: how the fluid carries the layer.
  if (const toml::table* ct = r.table(root, "", "coupling")) {
    if (!s.rd.enabled || !s.hasFluid)
      r.fail(ct, "coupling", "[coupling] joins a [fluid] and an [rd] layer, and this scene lacks one of them",
             "add the missing table or drop [coupling]");
  }
  if (s.rd.enabled && s.hasFluid) {
    const toml::table* ct = r.table(root, "", "coupling");
    CouplingScene& C = s.coupling;
    C.enabled = true;
    C.mode = r.string(ct, "coupling.", "mode", "ard", {"ard", "passive", "rd-only"});
    C.interpolation = r.string(ct, "coupling.", "interpolation", "linear", {"linear", "cubic"});
    C.rdTimeScale = r.number(ct, "coupling.", "rd_time_scale", 1.0, 0, 1e9, true);
    const size_t n = species.size();
    C.inflowValues = r.numbers(ct, "coupling.", "inflow_values", s.rd.initial.values, n, n, -1e12, 1e12);
    C.solidValues = r.numbers(ct, "coupling.", "solid_values", std::vector<double>(n, 0.0), n, n, -1e12, 1e12);
  }

  // Every spatial field is finite on the grid, and every fixed region holds a cell.
  if (s.rd.enabled) {
    std::vector<double> rres;
    for (int v : s.rd.settings.resolution) rres.push_back(v);
    auto check = [&](const SceneField& f, bool region, bool positive = false) {
      const std::vector<double> v = D == 2 ? sampleSpatialField<2>(f.field, IVec<2>(int(rres[0]), int(rres[1])))
                                           : sampleSpatialField<3>(f.field, IVec<3>(int(rres[0]), int(rres[1]), int(rres[2])));
      size_t inside = 0;
      auto cell = [&](size_t i) {
        std::ostringstream c;
        c << "cell (" << i % size_t(rres[0]) << ", " << (i / size_t(rres[0])) % size_t(rres[1]);
        if (D == 3) c << ", " << i / size_t(rres[0] * rres[1]);
        return c.str() + ")";
      };
      for (size_t i = 0; i < v.size(); ++i) {
        if (!std::isfinite(v[i]))
          throw UserError(f.where, f.key, "the field is not finite at " + cell(i),
                          "guard divisions and logarithms, e.g. 1 / max(r, 1e-6)");
        if (positive && !(v[i] > 0.0))
          throw UserError(f.where, f.key,
                          "a principal diffusivity must be > 0 (the tensor positive definite), but it is " +
                              (std::ostringstream() << v[i]).str() + " at " + cell(i),
                          "keep lambda1 and lambda2 positive everywhere, e.g. max(..., 0.1)");
        inside += v[i] != 0.0;
      }
      if (region && inside == 0)
        throw UserError(f.where, f.key, "no cell is inside this region",
                        "the expression must be nonzero somewhere, e.g. \"j == 0\" for the first row");
    };
    for (const auto& [k, f] : s.rd.initialMaps) check(f, false);
    for (const auto& [k, f] : s.rd.parameterMaps) check(f, false);
    for (const RDFixedRegion& fr : s.rd.fixed) check(fr.where, true);
    if (s.rd.anisotropy.enabled) {
      const RDAnisotropy& A = s.rd.anisotropy;
      check(A.lambda1, false, true);
      check(A.lambda2, false, true);
      if (A.direction.empty()) check(A.theta, false);
      for (const SceneField& f : A.direction) check(f, false);
    }
    if (s.rd.lobes.enabled) check(s.rd.lobes.theta0, false);
  }

  // [output]
  const toml::table* out = r.table(root, "", "output");
  s.output.every = int(r.integer(out, "output.", "every", 10, 1, 1'000'000'000));
  s.output.images = r.boolean(out, "output.", "images", true);
  s.output.fields = r.boolean(out, "output.", "fields", false);
  s.output.format = r.string(out, "output.", "format", "png", {"png", "exr"});
  if (r.boolean(out, "output.", "vdb", false))
    r.fail(r.node(out, "output.", "vdb"), "output.vdb", "this build of morphoflow does not write vdb yet",
           "set it to false");
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

  r.checkUnknown(root, "");

  // The scene as resolved, for run.json.
  std::ostringstream json;
  json << toml::json_formatter{root};
  s.resolvedJson = json.str();
  return s;
}

}  // namespace morphoflow
