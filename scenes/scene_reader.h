// Internal to scenes/: reads typed, range-checked values out of a scene's
// TOML tree, remembering which keys each table was asked for (whatever is
// left over is an unknown key), and the context the section parsers share.
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "core/error.h"
#include "render/image_io.h"
#include "scenes/scene.h"

namespace morphoflow {

std::string join(const std::vector<std::string>& v, const std::string& sep = ", ");
// The choice nearest to `word` by edit distance, for "did you mean".
std::string nearest(const std::string& word, const std::vector<std::string>& choices);
// "a string", "an integer", ...: what a node holds, for messages.
std::string describe(const toml::node& n);
// A number given where an expression may stand, as an expression's text:
// the shortest that reads back as the same double.
std::string numberText(double v);

class Reader {
 public:
  Reader(std::string file, toml::table& root, std::map<std::string, SourceLocation> overrideLocs)
      : file_(std::move(file)), root_(root), overrideLocs_(std::move(overrideLocs)) {}

  // Where key's node n came from: the file, or the --set that gave it or
  // a table or array around it (at n's column within the value).
  SourceLocation where(const toml::node* n, const std::string& key) const {
    for (std::string k = key;; k.resize(k.rfind('.'))) {
      if (auto it = overrideLocs_.find(k); it != overrideLocs_.end()) return withinOverride(it->second, n);
      if (k.find('.') == std::string::npos) break;
    }
    if (!n) return {file_, 0, 0};
    return {file_, int(n->source().begin.line), int(n->source().begin.column)};
  }
  // applyOverride parses "v = VALUE" and records VALUE's first column.
  static SourceLocation withinOverride(SourceLocation at, const toml::node* n) {
    constexpr int kValueColumn = 5;
    if (n && n->source().path && *n->source().path == at.file && n->source().begin.line == 1)
      at.column += int(n->source().begin.column) - kValueColumn;
    return at;
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
    const toml::node* n = t->get(key);
    if (n) given_.insert(prefix + key);
    return n;
  }

  double number(const toml::table* t, const std::string& prefix, const std::string& key, double def,
                double lo, double hi, bool loOpen = false) {
    const toml::node* n = node(t, prefix, key);
    const double v = n ? checkNumber(n, prefix + key, lo, hi, loOpen) : def;
    numeric_[prefix + key] = {lo, hi, loOpen, false, {v}};
    return v;
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
    numeric_[prefix + key] = {lo, hi, loOpen, true, def};
    if (!n) return def;
    const std::string full = prefix + key;
    const toml::array* arr = n->as_array();
    if (!arr) fail(n, full, "expected an array of numbers, found " + describe(*n));
    if (arr->size() < minLen || arr->size() > maxLen)
      fail(n, full,
           "expected " +
               (minLen == maxLen ? std::to_string(minLen) : std::to_string(minLen) + " or " + std::to_string(maxLen)) +
               " numbers, found " + std::to_string(arr->size()));
    std::vector<double> v;
    for (const toml::node& e : *arr) v.push_back(checkNumber(&e, full, lo, hi, loOpen));
    numeric_[full].values = v;
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
      f.field.expression = n->is_string() ? n->value<std::string>().value() : numberText(n->value<double>().value());
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
      fail(n, full,
           "expected an expression string or a table { image = \"file\", range = [low, high] }, found " + describe(*n));
    const toml::node* img = node(t, full + ".", "image");
    if (!img) fail(n, full, "an image field needs image = \"path\"");
    std::string file = string(t, full + ".", "image", "");
    std::filesystem::path fp =
        std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : sceneDir / file;
    GrayImage g;
    std::string err;
    if (!readGrayImage(fp.string(), &g, &err)) fail(img, full + ".image", "cannot read the image: " + err);
    noteInput(fp, img, full + ".image");
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

  // A file the scene reads (an image, a velocity volume), and the key that names it.
  void noteInput(const std::filesystem::path& path, const toml::node* n, const std::string& key) {
    inputs_.push_back({path.string(), where(n, key), key});
  }
  const std::vector<SceneInput>& inputs() const { return inputs_; }
  // Every number and array of numbers asked for, with its range and value.
  const std::map<std::string, KeyRange>& numericKeys() const { return numeric_; }
  const std::set<std::string>& givenKeys() const { return given_; }  // the keys the scene (or --set) gave

 private:
  std::string file_;
  toml::table& root_;
  std::map<std::string, SourceLocation> overrideLocs_;
  std::map<const toml::table*, std::set<std::string>> known_;
  std::vector<SceneInput> inputs_;
  std::map<std::string, KeyRange> numeric_;
  std::set<std::string> given_;
};

// An array of species names of `model` (one of `species`), as indices.
std::vector<int> speciesIndices(Reader& r, const toml::node* n, const std::string& key,
                                const std::vector<std::string>& species, const std::string& model, bool allowEmpty);

// The elements of `arr` as expressions in `vars` (a string, or a number as
// its text), each compiled here so that an error names its key (prefix.N)
// and column: "in the WHAT expression: ...", then `help`.
std::vector<std::string> expressionList(Reader& r, const toml::array& arr, const std::string& prefix,
                                        const std::vector<std::string>& vars, const std::string& what,
                                        const std::string& help);

// prefix+key as [low, high] with low < high, each within +-bound: empty
// when the key is absent.
std::vector<double> interval(Reader& r, const toml::table* t, const std::string& prefix, const std::string& key,
                             double bound);

// Applies one --set key.path=value override (the value in TOML syntax) and
// remembers where it came from, for messages.
void applyOverride(toml::table& root, const std::string& kv, std::map<std::string, SourceLocation>* locs);

// What the section parsers share: the reader, the tree, and what earlier
// sections resolved that later ones need.
struct SceneContext {
  SceneContext(Reader& reader, toml::table& tree, std::filesystem::path dir,
               const std::map<std::string, SourceLocation>& overrides)
      : r(reader), root(tree), sceneDir(std::move(dir)), overrideLocs(overrides) {}
  Reader& r;
  toml::table& root;
  std::filesystem::path sceneDir;
  const std::map<std::string, SourceLocation>& overrideLocs;
  int D = 2;
  bool rdOnly = false;              // [rd] without [fluid]
  bool givenVelocity = false;       // [velocity]: the [rd] layer is carried by a given field
  std::vector<double> res, size;    // [grid] cells and [domain] extent per axis
  int inflowSide = -1;              // index of the inflow side (x_min, x_max, ...), -1: none
  std::vector<std::string> species; // of the [rd] model
};

// A shape of [[obstacles]] or [[sources]] from table o (keys prefixed p).
ObstacleSpec parseRegion(SceneContext& c, const toml::table* o, const std::string& p);
// The array of tables [[name]] at the root (null when absent).
const toml::array* tableArray(Reader& r, toml::table& root, const std::string& name);

// One parser per scene section, in the order loadScene calls them; each
// fills its part of the Scene (scene.h) and reads only what earlier ones
// resolved.
void parseGrid(SceneContext& c, Scene* s);        // [grid], [domain]
void parseTime(SceneContext& c, Scene* s);        // [time]
void checkUntilSteady(SceneContext& c, const Scene& s);  // time.until_steady needs a fluid
void parseBoundary(SceneContext& c, Scene* s);    // [boundary], [inflow]
void parseObstacles(SceneContext& c, Scene* s);   // [[obstacles]]
void parseFluid(SceneContext& c, Scene* s);       // [fluid], [dye], [probes]
void parseSmoke(SceneContext& c, Scene* s);       // [smoke], [[sources]] (after [fluid] and [velocity])
void parseRD(SceneContext& c, Scene* s);          // [rd] and its tables
void parseStrokes(SceneContext& c, const toml::table& rd, RDScene* out);  // [[rd.strokes]] (called by parseRD)
void parseGeneralized(SceneContext& c, const toml::table& rd, Scene* s);  // [rd.generalized] (called by parseRD)
void parseVelocity(SceneContext& c, Scene* s);    // [velocity] (after [rd])
void parseCoupling(SceneContext& c, Scene* s);    // [coupling]
void parseOutput(SceneContext& c, Scene* s);      // [output]
void parseDeposits(SceneContext& c, Scene* s);    // [[deposits]] (after [rd] and [smoke])

// The timeline (scenes/timeline.h): every keyframed key of the tree, checked
// and replaced by its first value; an element's [start, end) (keys p+start, p+end).
std::vector<KeyedValue> extractKeyframes(Reader& r, toml::table& root);
TimeWindow parseWindow(Reader& r, const toml::table* t, const std::string& p);

}  // namespace morphoflow
