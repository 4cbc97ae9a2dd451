#include "scenes/scene_reader.h"

#include <sstream>

#include <fmt/format.h>

#include "core/expression.h"
#include "scenes/scene_loader.h"

namespace morphoflow {

std::string join(const std::vector<std::string>& v, const std::string& sep) {
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

std::string numberText(double v) { return fmt::format("{}", v); }

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
  // Moved, not copied: a copy drops the nodes' source positions.
  parsed.get("v")->visit([&](auto&& n) { t->insert_or_assign(parts.back(), std::move(n)); });
  (*locs)[key] = {origin, 1, int(eq) + 2};
}

std::vector<int> speciesIndices(Reader& r, const toml::node* n, const std::string& key,
                                const std::vector<std::string>& species, const std::string& model, bool allowEmpty) {
  std::vector<int> out;
  const toml::array* sa = n->as_array();
  if (!sa || (sa->empty() && !allowEmpty))
    r.fail(n, key, "expected an array of species names", "species: " + join(species));
  for (const toml::node& e : *sa) {
    auto v = e.value<std::string>();
    auto f = v ? std::find(species.begin(), species.end(), *v) : species.end();
    if (f == species.end()) r.fail(&e, key, "expected species names of " + model + ": " + join(species));
    out.push_back(int(f - species.begin()));
  }
  return out;
}

std::vector<std::string> expressionList(Reader& r, const toml::array& arr, const std::string& prefix,
                                        const std::vector<std::string>& vars, const std::string& what,
                                        const std::string& help) {
  std::vector<std::string> texts;
  for (size_t q = 0; q < arr.size(); ++q) {
    const toml::node* e = arr.get(q);
    const std::string key = prefix + "." + std::to_string(q);
    if (!e->is_string() && !e->is_number()) r.fail(e, key, "expected an expression string, found " + describe(*e));
    const std::string text = e->is_string() ? e->value<std::string>().value() : numberText(e->value<double>().value());
    try {
      Expression(text, vars);
    } catch (const ExpressionError& err) {
      SourceLocation at = r.where(e, key);
      if (at.line > 0 && e->is_string()) at.column += 1 + int(err.column());
      throw UserError(at, key, "in the " + what + " expression: " + err.what(), help);
    }
    texts.push_back(text);
  }
  return texts;
}

std::vector<double> interval(Reader& r, const toml::table* t, const std::string& prefix, const std::string& key,
                             double bound) {
  const toml::node* n = nullptr;
  std::vector<double> range = r.numbers(t, prefix, key, {}, 2, 2, -bound, bound, false, &n);
  if (!range.empty() && !(range[0] < range[1])) r.fail(n, prefix + key, "expected [low, high] with low < high");
  return range;
}

}  // namespace morphoflow
