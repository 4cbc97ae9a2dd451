#include "scenes/override_text.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

namespace morphoflow {

bool isDottedKey(std::string_view k) {
  const auto bare = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  };
  return !k.empty() && k.front() != '.' && k.back() != '.' && k.find("..") == std::string_view::npos &&
         std::all_of(k.begin(), k.end(), bare);
}

std::string tomlString(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\')
      out += std::string("\\") + c;
    else if (u < 0x20 || u == 0x7f)
      out += fmt::format("\\u{:04X}", u);
    else
      out += c;
  }
  return out + "\"";
}

}  // namespace morphoflow
