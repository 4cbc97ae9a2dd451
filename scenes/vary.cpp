#include "scenes/vary.h"

#include <cmath>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/error.h"
#include "core/number_text.h"

namespace morphoflow {

namespace {

constexpr long kMaxValues = 10000;

[[noreturn]] void bad(const std::string& text, const std::string& why) {
  throw UserError({"--vary " + text, 0, 0}, "", why,
                  "write --vary key=start:stop:count (e.g. rd.params.F=0.02:0.06:5) or --vary key=[a,b,c]");
}

// One TOML value as --set takes it, and as a label without quotes.
void addValue(const toml::node& n, Vary* v) {
  std::ostringstream s;
  if (const auto* str = n.as_string()) {
    s << toml::value<std::string>(str->get());
    v->labels.push_back(str->get());
  } else if (const auto* f = n.as_floating_point()) {
    // The shortest text that reads back as the same double (0.06, not 0.059999999999999998).
    std::string t = fmt::format("{}", f->get());
    if (t.find_first_of(".eEn") == std::string::npos) t += ".0";
    s << t;
    v->labels.push_back(t);
  } else {
    if (n.is_table()) s << toml::toml_formatter{*n.as_table()};
    else if (n.is_array()) s << *n.as_array();
    else n.visit([&s](const auto& x) { s << x; });
    v->labels.push_back(s.str());
  }
  v->values.push_back(s.str());
}

void listValues(const std::string& text, const std::string& list, Vary* v) {
  toml::table t;
  try {
    t = toml::parse("v = " + list, std::string_view("--vary"));
  } catch (const toml::parse_error& e) {
    bad(text, "the list is not a valid TOML array: " + std::string(e.description()));
  }
  const toml::array* a = t["v"].as_array();
  if (!a || a->empty()) bad(text, "the list of values is empty");
  if (long(a->size()) > kMaxValues) bad(text, fmt::format("more than {} values", kMaxValues));
  for (const toml::node& n : *a) addValue(n, v);
}

void rangeValues(const std::string& text, const std::string& range, Vary* v) {
  const size_t c1 = range.find(':'), c2 = range.find(':', c1 == std::string::npos ? c1 : c1 + 1);
  if (c1 == std::string::npos || c2 == std::string::npos || range.find(':', c2 + 1) != std::string::npos)
    bad(text, "expected start:stop:count or a list [a,b,c]");
  const std::string a = range.substr(0, c1), b = range.substr(c1 + 1, c2 - c1 - 1), c = range.substr(c2 + 1);
  const auto start = parseNumber(a), stop = parseNumber(b);
  const auto count = parseWhole(c);
  if (!start || !stop) bad(text, "start and stop must be numbers");
  if (!count || *count < 1 || *count > kMaxValues)
    bad(text, fmt::format("count must be a whole number from 1 to {}", kMaxValues));
  // Integers stay integers (grid sizes, step counts) when every value is whole.
  const bool whole =
      parseWhole(a) && parseWhole(b) && (*count == 1 || std::fmod(*stop - *start, double(*count - 1)) == 0.0);
  for (long i = 0; i < *count; ++i) {
    const double x = *count == 1 ? *start : *start + (*stop - *start) * double(i) / double(*count - 1);
    // 12 significant digits: 0.02:0.06:5 gives 0.03, not 0.030000000000000002.
    const std::string s =
        whole ? fmt::format("{}", std::llround(x)) : fmt::format("{}", std::stod(fmt::format("{:.12g}", x)));
    v->values.push_back(s);
    v->labels.push_back(s);
  }
}

}  // namespace

Vary parseVary(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) bad(text, "expected key=values");
  Vary v;
  v.key = text.substr(0, eq);
  for (char ch : v.key)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-'))
      bad(text, "'" + v.key + "' is not a scene key (letters, digits, '_', '-' and '.')");
  const std::string rhs = text.substr(eq + 1);
  if (!rhs.empty() && rhs.front() == '[') listValues(text, rhs, &v);
  else rangeValues(text, rhs, &v);
  return v;
}

std::vector<std::vector<size_t>> cartesianProduct(const std::vector<Vary>& varies) {
  std::vector<std::vector<size_t>> out{{}};
  for (const Vary& v : varies) {
    std::vector<std::vector<size_t>> next;
    for (const auto& prefix : out)
      for (size_t i = 0; i < v.values.size(); ++i) {
        next.push_back(prefix);
        next.back().push_back(i);
      }
    out = std::move(next);
  }
  return out;
}

}  // namespace morphoflow
