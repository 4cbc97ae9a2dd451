// The scene's timeline: keyframed keys (key = { keys = [[t, value], ...] }),
// [[deposits]], and the start and end times of strokes and obstacles
// (scenes/timeline.h).
#include <fmt/format.h>

#include "scenes/field_catalogue.h"
#include "scenes/scene_reader.h"

namespace morphoflow {

namespace {

// One keyframe table at `key` (the table n), checked: its keys in time order,
// each value a number or an array of numbers of one length.
KeyedValue parseKeyframes(Reader& r, const toml::table& t, const std::string& key) {
  KeyedValue k;
  k.key = key;
  k.where = r.where(&t, key);
  for (auto&& [name, v] : t)
    if (name.str() != "keys" && name.str() != "interpolation")
      r.fail(&v, key + "." + std::string(name.str()), "unknown key in a keyframed value",
             "a keyframed value is { keys = [[t, value], ...], interpolation = \"step\" or \"linear\" }");
  if (const toml::node* in = t.get("interpolation")) {
    const std::optional<std::string> s = in->value<std::string>();
    if (!s || (*s != "step" && *s != "linear"))
      r.fail(in, key + ".interpolation", "expected \"step\" or \"linear\", found " + describe(*in));
    k.linear = *s == "linear";
  } else {
    k.linear = true;
  }
  const toml::array* keys = t.get("keys") ? t.get("keys")->as_array() : nullptr;
  const std::string hint = "e.g. " + key + " = { keys = [[0, 0.03], [5, 0.05]] } (time, value)";
  if (!keys || keys->empty()) r.fail(&t, key + ".keys", "expected keys = [[t, value], ...], at least one", hint);
  for (size_t i = 0; i < keys->size(); ++i) {
    const toml::node* e = keys->get(i);
    const std::string at = key + ".keys." + std::to_string(i);
    const toml::array* pair = e->as_array();
    if (!pair || pair->size() != 2) r.fail(e, at, "expected a pair [t, value], found " + describe(*e), hint);
    const double time = r.checkNumber(pair->get(0), at, 0.0, 1e12, false);
    if (i > 0 && !(time > k.times.back()))
      r.fail(pair->get(0), at,
             fmt::format("the keys' times must increase: t = {:g} follows t = {:g}", time, k.times.back()));
    const toml::node* v = pair->get(1);
    std::vector<double> value;
    if (const toml::array* a = v->as_array()) {
      for (const toml::node& x : *a) value.push_back(r.checkNumber(&x, at, -1e300, 1e300, false));
      if (i == 0) k.array = true;
    } else {
      value.push_back(r.checkNumber(v, at, -1e300, 1e300, false));
    }
    if (i > 0 && (k.array != bool(v->as_array()) || value.size() != k.values[0].size()))
      r.fail(v, at, "every key's value must have the shape of the first one's");
    k.places.push_back(r.where(v, at));
    k.times.push_back(time);
    k.values.push_back(std::move(value));
  }
  return k;
}

// Walks the tree for keyframe tables, replacing each by its first value
// (moved, so that its position stays for the sections' messages).
void extract(Reader& r, toml::table& t, const std::string& prefix, std::vector<KeyedValue>* out) {
  std::vector<std::string> keyed;
  for (auto&& [name, v] : t) {
    const std::string key = prefix + std::string(name.str());
    if (toml::table* sub = v.as_table()) {
      if (!sub->contains("keys")) {
        extract(r, *sub, key + ".", out);
        continue;
      }
      if (!isSteerableKey(key))
        r.fail(sub, key, "this key cannot change during a run, so it takes no keyframes",
               "keyframes are for: " + join(steerableKeyPatterns()));
      out->push_back(parseKeyframes(r, *sub, key));
      keyed.push_back(std::string(name.str()));
    } else if (toml::array* a = v.as_array(); a && a->is_array_of_tables()) {
      for (size_t i = 0; i < a->size(); ++i)
        extract(r, *a->get(i)->as_table(), key + "." + std::to_string(i) + ".", out);
    }
  }
  for (const std::string& name : keyed) {
    toml::node* first = t.get(name)->as_table()->get("keys")->as_array()->get(0)->as_array()->get(1);
    first->visit([&](auto&& n) {
      std::decay_t<decltype(n)> moved(std::move(n));
      t.insert_or_assign(name, std::move(moved));
    });
  }
}

}  // namespace

std::vector<KeyedValue> extractKeyframes(Reader& r, toml::table& root) {
  std::vector<KeyedValue> keyed;
  extract(r, root, "", &keyed);
  return keyed;
}

void parseDeposits(SceneContext& c, Scene* s) {
  Reader& r = c.r;
  const toml::array* arr = tableArray(r, c.root, "deposits");
  if (!arr) return;
  const std::vector<std::string> fields = FieldCatalogue(*s).settableNames();
  for (size_t i = 0; i < arr->size(); ++i) {
    const toml::table* t = arr->get(i)->as_table();
    const std::string p = "deposits." + std::to_string(i) + ".";
    Deposit d;
    d.where = r.where(t, p.substr(0, p.size() - 1));
    d.time = r.number(t, p, "t", 0.0, 0.0, 1e12);
    if (!r.node(t, p, "field")) r.fail(t, p + "field", "a deposit needs the field it sets", "one of: " + join(fields));
    d.field = r.string(t, p, "field", "", fields);
    std::vector<double> centre(size_t(c.D), 0.0);
    const toml::node* cn = nullptr;
    centre = r.numbers(t, p, "center", centre, size_t(c.D), size_t(c.D), -1e9, 1e9, false, &cn);
    if (!cn) r.fail(t, p + "center", "a deposit needs its centre (domain units)");
    for (int a = 0; a < c.D; ++a) {
      if (centre[size_t(a)] < 0 || centre[size_t(a)] > c.size[size_t(a)])
        r.fail(cn, p + "center", "the centre lies outside the domain",
               fmt::format("domain.size is {:g} along axis {}", c.size[size_t(a)], a));
      d.center[size_t(a)] = centre[size_t(a)];
    }
    if (!r.node(t, p, "radius")) r.fail(t, p + "radius", "a deposit needs a radius (domain units)");
    d.radius = r.number(t, p, "radius", 0.0, 0.0, 1e9, true);
    if (!r.node(t, p, "value")) r.fail(t, p + "value", "a deposit needs the value it sets");
    d.value = r.number(t, p, "value", 0.0, -1e12, 1e12);
    s->timeline.deposits.push_back(d);
  }
  std::stable_sort(s->timeline.deposits.begin(), s->timeline.deposits.end(),
                   [](const Deposit& a, const Deposit& b) { return a.time < b.time; });
}

TimeWindow parseWindow(Reader& r, const toml::table* t, const std::string& p) {
  TimeWindow w;
  w.start = r.number(t, p, "start", 0.0, 0.0, 1e12);
  w.end = r.number(t, p, "end", w.end, 0.0, 1e300);
  if (!(w.end > w.start))
    r.fail(r.node(t, p, "end"), p + "end",
           fmt::format("it ends (t = {:g}) before it starts (t = {:g})", w.end, w.start),
           "give end > start, or leave end out");
  return w;
}

}  // namespace morphoflow
