#include "render/colormap.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace morphoflow {

namespace {
using Stops = std::vector<std::array<uint8_t, 3>>;

const std::map<std::string, Stops>& maps() {
  static const std::map<std::string, Stops> m = {
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

std::vector<std::string> colormapNames() {
  std::vector<std::string> names;
  for (const auto& [k, v] : maps()) names.push_back(k);
  return names;
}

bool hasColormap(const std::string& name) { return maps().count(name) > 0; }

std::array<uint8_t, 3> colormap(const std::string& name, double t) {
  auto it = maps().find(name);
  const Stops& s = it != maps().end() ? it->second : maps().at("grayscale");
  if (!std::isfinite(t)) t = 0.0;
  t = std::clamp(t, 0.0, 1.0) * double(s.size() - 1);
  size_t i = std::min(size_t(t), s.size() - 2);
  double f = t - double(i);
  std::array<uint8_t, 3> c;
  for (int k = 0; k < 3; ++k)
    c[size_t(k)] = uint8_t(std::lround(s[i][size_t(k)] + f * (s[i + 1][size_t(k)] - s[i][size_t(k)])));
  return c;
}

}  // namespace morphoflow
