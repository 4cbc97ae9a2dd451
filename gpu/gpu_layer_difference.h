// A GPU reaction-diffusion layer held against the CPU's: the random state
// near the model's initial values both start from, and how far apart they
// are after stepping, relative to how far the CPU's moved
// (gpu_newton_check.cpp, and the parity tests).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/random.h"
#include "gpu/gpu_rd_layer.h"
#include "rd/rd_solver.h"

namespace morphoflow {

// Sets every species to its initial value +- 5% (of 1 + |value|), uniform
// noise from `seed`; returns the values set, per species.
template <int D>
std::vector<std::vector<double>> perturbNearInitial(RDSolver<D>* rd, uint64_t seed) {
  const ModelInfo& info = rd->model().info();
  std::vector<std::vector<double>> start(info.species.size());
  for (size_t k = 0; k < start.size(); ++k) {
    const double v = info.initial[k];
    Grid<double, D>& f = rd->field(int(k));
    for (size_t i = 0; i < f.size(); ++i)
      f[i] = v + 0.1 * (1.0 + std::abs(v)) * (uniform01(seed, uint64_t(k), i) - 0.5);
    start[k] = f.values();
  }
  return start;
}

// The largest difference between the layers, the largest change of the
// CPU's from `start`, over every species and cell, and the cells where some
// species differs by more than `relative` times that change.
struct LayerDifference {
  double worst = 0.0, moved = 0.0;
  size_t apart = 0;
};
template <int D>
LayerDifference layerDifference(const GpuRDLayer<D>& gpu, const RDSolver<D>& cpu,
                                const std::vector<std::vector<double>>& start, double relative = 0.0) {
  LayerDifference d;
  std::vector<double> cellWorst(cpu.field(0).size(), 0.0);
  for (size_t k = 0; k < start.size(); ++k) {
    const std::vector<double> g = gpu.download(int(k));
    const Grid<double, D>& c = cpu.field(int(k));
    for (size_t i = 0; i < g.size(); ++i) {
      cellWorst[i] = std::max(cellWorst[i], std::abs(g[i] - c[i]));
      d.moved = std::max(d.moved, std::abs(c[i] - start[k][i]));
    }
  }
  for (double w : cellWorst) {
    d.worst = std::max(d.worst, w);
    if (w > relative * d.moved) ++d.apart;
  }
  return d;
}

}  // namespace morphoflow
