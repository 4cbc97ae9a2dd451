#include "render/colormap.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

namespace morphoflow {

namespace {
const std::map<std::string, std::vector<Rgb8>>& maps() {
  static const std::map<std::string, std::vector<Rgb8>> m = {
      {"viridis", {{68, 1, 84}, {71, 45, 123}, {59, 82, 139}, {44, 114, 142}, {33, 145, 140},
                   {40, 174, 128}, {94, 201, 98}, {173, 220, 48}, {253, 231, 37}}},
      {"magma", {{0, 0, 4}, {28, 16, 68}, {79, 18, 123}, {129, 37, 129}, {181, 54, 122},
                 {229, 80, 100}, {251, 135, 97}, {254, 194, 135}, {252, 253, 191}}},
      {"inferno", {{0, 0, 4}, {31, 12, 72}, {85, 15, 109}, {136, 34, 106}, {186, 54, 85},
                   {227, 89, 51}, {249, 140, 10}, {249, 201, 50}, {252, 255, 164}}},
      {"coolwarm", {{59, 76, 192}, {98, 130, 234}, {141, 176, 254}, {184, 208, 249}, {221, 221, 221},
                    {245, 196, 173}, {244, 154, 123}, {222, 96, 77}, {180, 4, 38}}},
      {"grayscale", {{0, 0, 0}, {255, 255, 255}}},
  };
  return m;
}
}  // namespace

Rgb8 Palette::operator()(double t) const {
  const std::vector<Rgb8>& s = stops;
  if (!std::isfinite(t)) t = 0.0;
  t = std::clamp(t, 0.0, 1.0) * double(s.size() - 1);
  size_t i = std::min(size_t(t), s.size() - 2);
  double f = t - double(i);
  Rgb8 c;
  for (size_t k = 0; k < 3; ++k) c[k] = uint8_t(std::lround(s[i][k] + f * (s[i + 1][k] - s[i][k])));
  return c;
}

std::vector<std::string> colormapNames() {
  std::vector<std::string> names;
  for (const auto& [k, v] : maps()) names.push_back(k);
  names.push_back(kTwoSpeciesPalette);
  return names;
}

Palette namedPalette(const std::string& name) {
  auto it = maps().find(name);
  return Palette{it != maps().end() ? it->second : maps().at("grayscale")};
}

bool parseHexColour(const std::string& text, Rgb8* colour) {
  std::string h = !text.empty() && text[0] == '#' ? text.substr(1) : text;
  if (h.size() != 6 || !std::all_of(h.begin(), h.end(), [](unsigned char c) { return std::isxdigit(c); }))
    return false;
  for (size_t k = 0; k < 3; ++k) (*colour)[k] = uint8_t(std::stoi(h.substr(2 * k, 2), nullptr, 16));
  return true;
}

}  // namespace morphoflow
