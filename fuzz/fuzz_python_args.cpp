// libFuzzer target for the Python module's set= arguments, through the
// functions the module builds its overrides with (scenes/override_text.h):
// a key and a value given apart become one "key=value" override. An input
// is a kind byte (0: a string value, 1: a float, as Python's repr writes
// it; 2: a bool; 3: a list of strings split at byte 1), the key, byte 0,
// and the value. A key the module takes must set exactly that key to exactly
// that value, whatever quotes, '=', newlines or control characters either
// holds; and a coupled scene with the override is read without anything
// but a UserError.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "fuzz/fuzz_support.h"
#include "scenes/override_text.h"
#include "scenes/scene_loader.h"
#include "scenes/scene_reader.h"

using namespace morphoflow;

namespace {

// The value's TOML text, as python/module.cpp writes it, and a check of what the override set.
struct Value {
  std::string toml;
  std::vector<std::string> strings;  // kinds 0 and 3
  double number = 0.0;
  bool flag = false;
};

Value valueOf(int kind, std::string_view bytes) {
  Value v;
  if (kind == 1) {
    char raw[8] = {};
    std::memcpy(raw, bytes.data(), std::min<size_t>(8, bytes.size()));
    std::memcpy(&v.number, raw, 8);
    // Python's repr: the shortest text that reads back, "1.0" not "1", "nan" whatever its sign.
    v.toml = std::isnan(v.number) ? "nan" : fmt::format("{}", v.number);
    if (v.toml.find_first_of(".eEn") == std::string::npos) v.toml += ".0";
  } else if (kind == 2) {
    v.flag = !bytes.empty() && (bytes[0] & 1);
    v.toml = v.flag ? "true" : "false";
  } else if (kind == 0) {
    v.strings = {std::string(bytes)};
    v.toml = tomlString(bytes);
  } else {
    std::string item;
    std::stringstream s{std::string(bytes)};
    v.toml = "[";
    while (std::getline(s, item, '\x01')) {
      v.toml += (v.strings.empty() ? "" : ",") + tomlString(item);
      v.strings.push_back(item);
    }
    v.toml += "]";
  }
  return v;
}

bool sameValue(int kind, const Value& v, const toml::node& n) {
  if (kind == 1) {
    const auto d = n.value<double>();
    return n.is_floating_point() && d && (std::isnan(v.number) ? std::isnan(*d) : *d == v.number);
  }
  if (kind == 2) return n.is_boolean() && n.value<bool>() == v.flag;
  if (kind == 0) return n.is_string() && n.value<std::string>() == v.strings[0];
  const toml::array* a = n.as_array();
  if (!a || a->size() != v.strings.size()) return false;
  for (size_t i = 0; i < a->size(); ++i)
    if (a->get(i)->value<std::string>() != v.strings[i]) return false;
  return true;
}

long leaves(const toml::table& t) {
  long n = 0;
  for (const auto& [k, node] : t) n += node.is_table() ? leaves(*node.as_table()) : 1;
  return n;
}

// The override alone, on an empty scene: one leaf, at the key, holding the value.
void checkSetsOnlyItsKey(const std::string& key, int kind, const Value& v) {
  toml::table root;
  std::map<std::string, SourceLocation> locs;
  try {
    applyOverride(root, key + "=" + v.toml, &locs);
  } catch (const UserError&) {
    if (kind == 2) fuzz::finding("a bool override was refused: " + key);
    return;  // (a string that is not UTF-8, a number TOML cannot hold)
  }
  const toml::node* at = &root;
  std::stringstream parts(key);
  for (std::string p; at && std::getline(parts, p, '.');) at = at->as_table() ? at->as_table()->get(p) : nullptr;
  if (!at || leaves(root) != 1 || !sameValue(kind, v, *at))
    fuzz::finding("set={'" + key + "': ...} as '" + key + "=" + v.toml + "' set something else");
}

void writeSeeds(const std::filesystem::path& dir) {
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"name", std::string(1, '\0') + "a\nfluid.reynolds=1"},
      {"output.field", std::string(1, '\0') + "v\" \n rd.model = \"brusselator"},
      {"fluid.reynolds", std::string(1, '\1') + std::string("\0\0\0\0\0\0\x59\x40", 8)},
      {"output.vdb", std::string(1, '\2') + "\1"},
      {"output.vdb_fields", std::string(1, '\3') + "dye\1vel\1u=v\\"},
      {"sources.0.radius", std::string(1, '\1') + std::string("\0\0\0\0\0\0\xf0\x7f", 8)},
  };
  int i = 0;
  for (const auto& [key, rest] : seeds)
    fuzz::writeBytes(dir / ("seed-" + std::to_string(i++)),
                     rest.substr(0, 1) + key + std::string(1, '\0') + rest.substr(1));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::writeSeedsIfAsked(writeSeeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int kind = data[0] & 3;
  const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  const size_t zero = rest.find('\0');
  if (zero == std::string_view::npos) return 0;
  const std::string key(rest.substr(0, zero));
  if (!isDottedKey(key)) return 0;  // the module raises a ValueError naming it
  const Value v = valueOf(kind, rest.substr(zero + 1));
  checkSetsOnlyItsKey(key, kind, v);
  static const std::string scene = MORPHOFLOW_SCENE_DIR "/coupled/cavity_gray_scott.toml";
  fuzz::expectUserErrorsOnly([&] { loadScene(scene, {key + "=" + v.toml}); });
  return 0;
}
