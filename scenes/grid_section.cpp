// [grid] and [domain]: the cells, the dimension and the extent of the box.
#include <fmt/format.h>

#include "scenes/scene_reader.h"

#include <cmath>
#include <sstream>

namespace morphoflow {

void parseGrid(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  toml::table& root = c.root;
  Scene& s = *sp;
  const toml::table* grid = r.table(root, "", "grid");
  const toml::node* resNode = nullptr;
  std::vector<double> res = r.numbers(grid, "grid.", "resolution", {128, 128}, 2, 3, 4, 8192, false, &resNode);
  for (double v : res)
    if (v != std::floor(v)) r.fail(resNode, "grid.resolution", "cell counts must be whole numbers");
  s.dimension = int(res.size());
  const int D = s.dimension;
  double cells = 1;
  for (double v : res) cells *= v;
  if (cells > double(1 << 28))
    r.fail(resNode, "grid.resolution", "the grid has too many cells for this machine's memory",
           "at most 268435456 cells");
  // Reaction-diffusion-only scenes default to unit cells (the seeds' units);
  // fluid scenes to a unit-wide box.
  const bool rdOnly = root.contains("rd") && !root.contains("fluid");
  std::vector<double> defSize;
  for (double v : res) defSize.push_back(rdOnly ? v : v / res[0]);
  const toml::table* domain = r.table(root, "", "domain");
  const toml::node* sizeNode = nullptr;
  std::vector<double> size =
      r.numbers(domain, "domain.", "size", defSize, size_t(D), size_t(D), 0, 1e9, true, &sizeNode);
  const double h = size[0] / res[0];
  // Below this, positions and back-traces in cells lose all precision.
  if (!(h >= 1e-9))
    r.fail(sizeNode ? sizeNode : resNode, "domain.size",
           fmt::format("cells of {:g} are smaller than 1e-9 domain units", h),
           "use larger domain.size (units are arbitrary)");
  for (int a = 1; a < D; ++a)
    if (std::abs(size[size_t(a)] / res[size_t(a)] - h) > 1e-6 * h) {
      std::ostringstream hint;
      hint << "cells must be square: use domain.size = [";
      for (int b = 0; b < D; ++b) hint << (b ? ", " : "") << h * res[size_t(b)];
      hint << "] or change grid.resolution";
      r.fail(sizeNode ? sizeNode : resNode, "domain.size", "size / resolution differs between axes", hint.str());
    }
  s.fluid.resolution.clear();
  for (double v : res) s.fluid.resolution.push_back(int(v));
  s.fluid.size = size;

  c.D = D;
  c.rdOnly = rdOnly;
  c.givenVelocity = root.contains("velocity");
  c.res = res;
  c.size = size;
}

}  // namespace morphoflow
