// Small fixed-size vectors for positions and lattice coordinates (GLM).
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace morphoflow {

template <int D>
using IVec = glm::vec<D, int>;
template <int D>
using Vec = glm::vec<D, double>;

template <int D>
IVec<D> unitVector(int axis) {
  IVec<D> e(0);
  e[axis] = 1;
  return e;
}

}  // namespace morphoflow
