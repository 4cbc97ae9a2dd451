#include "python/python_velocity.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.h"

namespace py = pybind11;

namespace morphoflow {

namespace {

const char* const kAxes[] = {"x", "y", "z"};

// Copies a float64-convertible array of `dims` (x fastest: numpy shape reversed) into g.
template <int D>
void fill(const py::object& values, Grid<float, D>* g, const std::string& what) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a(values);
  const IVec<D> n = g->dims();
  bool fits = a.ndim() == D;
  for (int k = 0; fits && k < D; ++k) fits = a.shape(D - 1 - k) == n[k];
  if (!fits) {
    std::string want;
    for (int k = D - 1; k >= 0; --k) want += (want.empty() ? "" : ", ") + std::to_string(n[k]);
    throw py::value_error(what + " has the wrong shape: expected (" + want + ")");
  }
  const double* p = a.data();
  for (size_t i = 0; i < g->size(); ++i) {
    if (!std::isfinite(p[i])) throw py::value_error(what + " holds a NaN or an infinity");
    (*g)[i] = float(p[i]);
  }
}

}  // namespace

template <int D>
void PythonVelocity<D>::set(py::object source) { source_ = std::move(source); }

template <int D>
void PythonVelocity<D>::sample(double t, MacVelocity<D>* u) {
  {
    py::gil_scoped_acquire gil;
    sampleFromPython(t, u);
  }
  wrapPeriodicFaces<D>(u);
}

template <int D>
void PythonVelocity<D>::sampleFromPython(double t, MacVelocity<D>* u) {
  if (!source_ || source_.is_none()) {  // not set yet: at rest
    for (int a = 0; a < D; ++a) (*u)[a].values().assign((*u)[a].size(), 0.0f);
    return;
  }
  const IVec<D> cells = u->cells();
  if (PyCallable_Check(source_.ptr())) {
    for (int a = 0; a < D; ++a) {  // the callable at component a's faces
      Grid<float, D>& g = (*u)[a];
      py::list coords;
      for (int b = 0; b < D; ++b) {
        std::vector<py::ssize_t> shape;
        for (int k = D - 1; k >= 0; --k) shape.push_back(g.dims()[k]);
        py::array_t<double> x(shape);
        double* p = x.mutable_data();
        for (size_t i = 0; i < g.size(); ++i) p[i] = u->layout(a).toWorld(g.coord(i))[b];
        coords.append(x);
      }
      coords.append(t);
      const py::object r = source_(*py::tuple(coords));
      const py::sequence parts = r.cast<py::sequence>();
      if (py::len(parts) != size_t(D))
        throw py::value_error("the velocity callable must return " + std::to_string(D) + " arrays (u, v" +
                              (D == 3 ? ", w" : "") + ")");
      fill<D>(parts[size_t(a)], &g, std::string("the velocity's ") + kAxes[a] + " component");
    }
    return;
  }
  // Arrays: D arrays on the faces, or one (D, ...) array at the cell centres.
  const py::array all = py::array::ensure(source_);
  if (all && all.ndim() == D + 1 && all.shape(0) == D) {
    for (int a = 0; a < D; ++a) {
      Grid<float, D> centre(cells, 0.0f);
      fill<D>(all[py::int_(a)], &centre, std::string("the velocity's ") + kAxes[a] + " component");
      Grid<float, D>& g = (*u)[a];
      for (size_t i = 0; i < g.size(); ++i) {  // the mean of the cells beside the face
        IVec<D> k = g.coord(i), lo = k;
        lo[a] -= 1;
        if (k[a] == cells[a]) k[a] -= 1;
        if (lo[a] < 0) lo[a] = 0;
        g[i] = float(0.5 * (double(centre(lo)) + double(centre(k))));
      }
    }
    return;
  }
  const py::sequence faces = source_.cast<py::sequence>();
  if (py::len(faces) != size_t(D))
    throw py::value_error("set_velocity takes a callable, a (" + std::to_string(D) +
                          ", ...) array at the cell centres, or one array per component on its faces");
  for (int a = 0; a < D; ++a) fill<D>(faces[size_t(a)], &(*u)[a], std::string("the velocity's ") + kAxes[a] + " faces");
}

template class PythonVelocity<2>;
template class PythonVelocity<3>;

}  // namespace morphoflow
