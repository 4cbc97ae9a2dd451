#include "studio/edit_log.h"

#include <algorithm>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "scenes/scene_loader.h"

namespace morphoflow {

namespace {

const SourceLocation kStudio{"studio", 0, 0};

toml::table readTree(const std::string& text, const std::string& path) {
  try {
    return toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw UserError({path, int(e.source().begin.line), int(e.source().begin.column)}, "",
                    "not valid TOML: " + std::string(e.description()));
  }
}

std::string writeTree(const toml::table& t) {
  std::ostringstream s;
  s << toml::toml_formatter{t};
  return s.str() + "\n";
}

std::vector<std::string> split(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  return parts;
}

// The table that holds key's last part (tables made on the way; an array's element by index).
toml::table* parentOf(toml::table& root, const std::vector<std::string>& parts) {
  toml::node* cur = &root;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    if (toml::array* a = cur->as_array()) {
      const std::string& n = parts[i];
      if (n.empty() || n.size() > 9 || !std::all_of(n.begin(), n.end(), [](char c) { return c >= '0' && c <= '9'; }))
        return nullptr;  // (not an index)
      const size_t idx = std::stoul(n);
      if (idx >= a->size()) return nullptr;
      cur = a->get(idx);
      continue;
    }
    toml::table* t = cur->as_table();
    if (!t) return nullptr;
    if (!t->contains(parts[i])) t->insert(parts[i], toml::table{});
    cur = t->get(parts[i]);
  }
  return cur->as_table();
}

// A JSON value as a TOML node's value (numbers as floats, except integers
// given as such), inserted into t at key.
void insertJson(toml::table& t, const std::string& key, const nlohmann::json& v);

toml::array jsonArray(const nlohmann::json& v) {
  toml::array a;
  for (const nlohmann::json& e : v) {
    toml::table holder;
    insertJson(holder, "v", e);
    holder.get("v")->visit([&](auto&& n) { a.push_back(std::move(n)); });
  }
  return a;
}

void insertJson(toml::table& t, const std::string& key, const nlohmann::json& v) {
  if (v.is_number_integer()) t.insert_or_assign(key, v.get<int64_t>());
  else if (v.is_number()) t.insert_or_assign(key, v.get<double>());
  else if (v.is_boolean()) t.insert_or_assign(key, v.get<bool>());
  else if (v.is_string()) t.insert_or_assign(key, v.get<std::string>());
  else if (v.is_array()) t.insert_or_assign(key, jsonArray(v));
  else
    throw UserError(kStudio, key, "expected a number, string, boolean or array, found " + std::string(v.type_name()));
}

toml::array numberArray(const std::vector<double>& v) {
  toml::array a;
  for (double x : v) a.push_back(x);
  return a;
}

// A number or an array of numbers from JSON.
std::vector<double> numbersOf(const std::string& key, const nlohmann::json& v) {
  std::vector<double> out;
  if (v.is_number()) return {v.get<double>()};
  if (v.is_array() && !v.empty())
    for (const nlohmann::json& e : v) {
      if (!e.is_number()) throw UserError(kStudio, key, "expected an array of numbers");
      out.push_back(e.get<double>());
    }
  if (out.empty()) throw UserError(kStudio, key, "expected a number or an array of numbers, found " + v.dump());
  return out;
}

toml::array& arrayOf(toml::table& root, const std::string& name) {
  const std::vector<std::string> parts = split(name);
  toml::table* parent = parentOf(root, parts);
  if (!parent->contains(parts.back())) parent->insert(parts.back(), toml::array{});
  toml::array* a = parent->get(parts.back())->as_array();
  if (!a) throw UserError(kStudio, name, "the scene's " + name + " is not an array of tables");
  return *a;
}

// "obstacles.3" / "sources.0" / "rd.strokes.1": the array and the index.
std::pair<std::string, size_t> target(const nlohmann::json& edit, const Scene& s) {
  const std::string t = edit.value("target", "");
  const size_t dot = t.rfind('.');
  const std::string name = dot == std::string::npos ? "" : t.substr(0, dot);
  if (name != "obstacles" && name != "sources")
    throw UserError(kStudio, "target", "expected \"obstacles.N\" or \"sources.N\", found \"" + t + "\"");
  size_t idx = 0;
  try {
    idx = std::stoul(t.substr(dot + 1));
  } catch (const std::exception&) {
    throw UserError(kStudio, "target", "expected \"obstacles.N\" or \"sources.N\", found \"" + t + "\"");
  }
  const size_t n = name == "obstacles" ? s.fluid.obstacles.size() : s.fluid.smoke.sources.size();
  if (idx >= n) throw UserError(kStudio, "target", fmt::format("the scene has {} {}", n, name));
  return {name, idx};
}

}  // namespace

EditLog::EditLog(const std::string& text, const std::string& path) : path_(path) {
  commit(writeTree(readTree(text, path)));
}

void EditLog::commit(std::string text) {
  scene_ = parseScene(text, path_);
  text_ = std::move(text);
}

std::string EditLog::text() const { return text_; }

void EditLog::set(const std::string& key, const nlohmann::json& value, double t) {
  if (!isSteerableKey(key))
    throw UserError(kStudio, key, "not a key the studio steers",
                    "steerable keys: " + fmt::format("{}", fmt::join(steerableKeyPatterns(), ", ")));
  const auto it = scene_.numericKeys.find(key);
  if (it == scene_.numericKeys.end()) throw UserError(kStudio, key, "this scene has no such key");
  const std::vector<double> v = numbersOf(key, value), now = it->second.values;
  if (v.size() != now.size())
    throw UserError(kStudio, key,
                    fmt::format("expected {} number{}, found {}", now.size(), now.size() > 1 ? "s" : "", v.size()));
  const bool array = value.is_array();
  toml::table tree = readTree(text_, path_);
  const std::vector<std::string> parts = split(key);
  toml::table* parent = parentOf(tree, parts);
  if (!parent) throw UserError(kStudio, key, "this scene has no such key");
  auto valueNode = [&](const std::vector<double>& x) {
    toml::array pair;
    if (array) pair.push_back(numberArray(x));
    else pair.push_back(x[0]);
    return pair;
  };
  toml::node* leaf = parent->get(parts.back());
  toml::table* keyed = leaf ? leaf->as_table() : nullptr;
  if (keyed && keyed->contains("keys")) {
    toml::array& keys = *keyed->get("keys")->as_array();
    const double last = keys.back().as_array()->get(0)->value<double>().value_or(0.0);
    if (last == t) keys.erase(keys.end() - 1);
    toml::array pair{t};
    pair.push_back(valueNode(v)[0]);
    keys.push_back(std::move(pair));
  } else if (t == 0.0) {
    if (array) parent->insert_or_assign(parts.back(), numberArray(v));
    else parent->insert_or_assign(parts.back(), v[0]);
  } else {
    toml::array first{0.0}, second{t};
    first.push_back(valueNode(now)[0]);
    second.push_back(valueNode(v)[0]);
    toml::table k;
    k.insert("keys", toml::array{std::move(first), std::move(second)});
    k.insert("interpolation", "step");
    parent->insert_or_assign(parts.back(), std::move(k));
  }
  commit(writeTree(tree));
}

void EditLog::paint(const nlohmann::json& edit, double t) {
  if (!edit.is_object()) throw UserError(kStudio, "", "a paint edit is a JSON object with a \"kind\"");
  const std::string kind = edit.value("kind", "");
  toml::table tree = readTree(text_, path_);
  static const std::map<std::string, std::pair<std::string, std::set<std::string>>> adds = {
      {"deposit", {"deposits", {"field", "center", "radius", "value"}}},
      {"stroke", {"rd.strokes", {"points", "width", "species", "values"}}},
      {"source", {"sources", {"shape", "center", "radius", "size", "density", "temperature", "velocity", "chemicals"}}},
      {"obstacle", {"obstacles", {"shape", "center", "radius", "size", "boundary"}}}};
  if (const auto add = adds.find(kind); add != adds.end()) {
    toml::table entry;
    for (const auto& [k, v] : edit.items()) {
      if (k == "kind") continue;
      if (!add->second.second.count(k))
        throw UserError(kStudio, k, "not a key of a " + kind,
                        "keys: " + fmt::format("{}", fmt::join(add->second.second, ", ")));
      insertJson(entry, k, v);
    }
    if (kind == "deposit") entry.insert("t", t);
    else if (t > 0.0) entry.insert("start", t);
    arrayOf(tree, add->second.first).push_back(std::move(entry));
  } else if (kind == "move" || kind == "erase") {
    const auto [name, idx] = target(edit, scene_);
    toml::array& a = arrayOf(tree, name);
    toml::table& old = *a.get(idx)->as_table();
    // An element that starts now (at the scene's start, or added at this
    // time) changes in place: it never existed elsewhere.
    const bool startsNow = old["start"].value_or(0.0) == t;
    if (kind == "move") {
      toml::table moved = old;
      insertJson(moved, "center", edit.value("center", nlohmann::json()));
      if (startsNow) {
        old = std::move(moved);
      } else {
        moved.erase("end");
        moved.insert_or_assign("start", t);
        if (const toml::node* e = old.get("end")) moved.insert("end", *e);  // (a source keeps its window's end)
        old.insert_or_assign("end", t);
        a.push_back(std::move(moved));
      }
    } else if (startsNow) {
      a.erase(a.begin() + std::ptrdiff_t(idx));
    } else {
      old.insert_or_assign("end", t);
    }
  } else {
    throw UserError(
        kStudio, "kind",
        "expected \"deposit\", \"stroke\", \"source\", \"obstacle\", \"move\" or \"erase\", found \"" + kind + "\"");
  }
  commit(writeTree(tree));
}

void EditLog::collapse() {
  toml::table tree = readTree(text_, path_);
  for (const KeyedValue& k : scene_.timeline.keyed) {
    const std::vector<std::string> parts = split(k.key);
    toml::table* parent = parentOf(tree, parts);
    const std::vector<double> v = k.values.back();
    if (k.array) parent->insert_or_assign(parts.back(), numberArray(v));
    else parent->insert_or_assign(parts.back(), v[0]);
  }
  // (sources keep their windows: a source's start and end are its own)
  for (const std::string name : {"obstacles", "rd.strokes"}) {
    const std::vector<std::string> parts = split(name);
    toml::table* parent = parentOf(tree, parts);
    toml::array* a = parent && parent->get(parts.back()) ? parent->get(parts.back())->as_array() : nullptr;
    if (!a) continue;
    for (size_t i = a->size(); i-- > 0;) {
      toml::table& e = *a->get(i)->as_table();
      if (e.get("end")) a->erase(a->begin() + std::ptrdiff_t(i));
      else e.erase("start");
    }
  }
  tree.erase("deposits");
  commit(writeTree(tree));
}

}  // namespace morphoflow
