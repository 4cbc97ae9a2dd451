#include "rd/texton_walk.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/random.h"

namespace morphoflow {

void checkTextonWalk(const TextonWalkSettings& s) {
  auto bad = [](const std::string& m) { throw std::invalid_argument(m); };
  if (s.width < 1 || s.height < 1) bad("the field needs at least 1 x 1 cells");
  if (s.elements < 1) bad("elements must be at least 1");
  if (s.steps < 0) bad("steps must be 0 or more");
  if (s.stepSize < 1) bad("the step size must be at least 1 cell");
  if (!(s.lifetime == 0.0 || s.lifetime >= 1.0)) bad("the lifetime L must be 0 (never expire) or at least 1 step");
  if (!(s.p >= 0 && s.q >= 0 && s.p + s.q <= 1.0 + 1e-12)) bad("p and q must be >= 0 with p + q <= 1");
  if (!(s.radius > 0)) bad("the texton radius must be positive");
}

std::vector<std::array<int, 2>> textonStart(const TextonWalkSettings& s) {
  std::vector<std::array<int, 2>> pos(size_t(s.elements));
  const int n = s.elements;
  if (s.start == TextonStart::Pulse) {
    std::fill(pos.begin(), pos.end(), std::array<int, 2>{s.width / 2, s.height / 2});
  } else if (s.start == TextonStart::Regular) {
    // The squarest lattice of at least n sites with the field's aspect ratio.
    int rows = std::max(1, int(std::lround(std::sqrt(double(n) * s.height / s.width))));
    int cols = (n + rows - 1) / rows;
    for (int e = 0; e < n; ++e)
      pos[size_t(e)] = {int((e % cols + 0.5) * s.width / cols), int((e / cols + 0.5) * s.height / rows)};
  } else {
    for (int e = 0; e < n; ++e)
      pos[size_t(e)] = {std::min(s.width - 1, int(uniform01(s.seed, 1, uint64_t(e)) * s.width)),
                        std::min(s.height - 1, int(uniform01(s.seed, 2, uint64_t(e)) * s.height))};
  }
  return pos;
}

bool textonStep(const TextonWalkSettings& s, uint64_t element, uint64_t step, std::array<int, 2>* at) {
  // One uniform per element and step decides among the six outcomes of eq. 6.
  double u = uniform01(s.seed, 1000 + element, step);
  const double expire = s.lifetime > 0 ? 1.0 / s.lifetime : 0.0;
  if (u < expire) return false;
  u = (u - expire) / (1.0 - expire);  // conditional on survival, uniform again
  int dx = 0, dy = 0;
  if (u < 0.5 * s.q) dx = -1, dy = 1;                        // upper left
  else if (u < s.q) dx = -1, dy = -1;                        // lower left
  else if (u < s.q + 0.5 * s.p) dx = 1, dy = 1;             // upper right
  else if (u < s.q + s.p) dx = 1, dy = -1;                   // lower right
  (*at)[0] = std::clamp((*at)[0] + dx * s.stepSize, 0, s.width - 1);  // placed on the boundary
  (*at)[1] = std::clamp((*at)[1] + dy * s.stepSize, 0, s.height - 1);
  return true;
}

std::vector<std::array<int, 2>> textonWalk(const TextonWalkSettings& s) {
  checkTextonWalk(s);
  std::vector<std::array<int, 2>> start = textonStart(s), alive;
  for (size_t e = 0; e < start.size(); ++e) {
    std::array<int, 2> p = start[e];
    bool ok = true;
    for (int k = 0; k < s.steps && ok; ++k) ok = textonStep(s, e, uint64_t(k), &p);
    if (ok) alive.push_back(p);
  }
  return alive;
}

std::vector<double> renderTextons(const std::vector<std::array<int, 2>>& positions, const TextonWalkSettings& s) {
  std::vector<double> img(size_t(s.width) * size_t(s.height), 0.0);
  const int r = int(std::ceil(s.radius)) + 1;
  for (const auto& p : positions)
    for (int y = std::max(0, p[1] - r); y <= std::min(s.height - 1, p[1] + r); ++y)
      for (int x = std::max(0, p[0] - r); x <= std::min(s.width - 1, p[0] + r); ++x) {
        // Coverage of the cell by a disc of the given radius, antialiased over one cell.
        double c = std::clamp(s.radius + 0.5 - std::hypot(x - p[0], y - p[1]), 0.0, 1.0);
        double& v = img[size_t(y) * size_t(s.width) + size_t(x)];
        v = std::max(v, c);
      }
  return img;
}

}  // namespace morphoflow
