// A given velocity ([velocity] python = true) that the Python module sets:
// a callable f(x, y[, z], t) -> (u, v[, w]) of numpy arrays, evaluated at
// each component's face positions (as ExpressionVelocity evaluates its
// expressions: world units, in double, stored as float), or fixed arrays,
// on the chemical grid's MAC faces or at its cell centres (then averaged to
// the faces; the outermost faces take the cell beside them).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "coupling/given_velocity.h"

namespace morphoflow {

template <int D>
class PythonVelocity : public GivenVelocity<D> {
 public:
  // What the next samples use: a callable, or arrays (checked against u's shape at the first sample).
  void set(pybind11::object source);
  void sample(double t, MacVelocity<D>* u) override;  // takes the GIL
  bool steady() const override { return false; }

 private:
  void sampleFromPython(double t, MacVelocity<D>* u);
  pybind11::object source_;  // None until set
};

}  // namespace morphoflow
