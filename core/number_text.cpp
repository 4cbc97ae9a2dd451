#include "core/number_text.h"

#include <charconv>
#include <cmath>

namespace morphoflow {

std::optional<long> parseWhole(const std::string& text) {
  long v = 0;
  const char* first = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
  const char* last = text.data() + text.size();
  const auto [end, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || end != last || first == last) return std::nullopt;
  return v;
}

std::optional<double> parseNumber(const std::string& text) {
  double v = 0;
  const char* first = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
  const char* last = text.data() + text.size();
  const auto [end, ec] = std::from_chars(first, last, v, std::chars_format::general);
  if (ec != std::errc() || end != last || first == last || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace morphoflow
