// The Python module's Scene and Simulation: a scene kept alive with the
// text it came from (for checkpoints), and a Simulation<2> or <3> on a
// backend, with the GIL released while it steps.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "core/simulation.h"
#include "python/python_velocity.h"
#include "scenes/scene.h"
#include "sim/backend.h"

namespace morphoflow {

struct PyScene {
  std::shared_ptr<Scene> scene;
  std::string text, path;              // its TOML text and the path it names
  std::vector<std::string> overrides;  // "key=value"
};

class PySimulation {
 public:
  PySimulation(const PyScene& scene, const std::string& backend, int threads);

  void step(long n);
  double time() const;
  long steps() const;
  std::vector<std::string> fieldNames() const;
  pybind11::array_t<float> field(const std::string& name) const;
  void setField(const std::string& name, const pybind11::object& values);
  void setVelocity(pybind11::object velocity);
  void save(const std::string& path) const;
  static PySimulation load(const std::string& path, const std::string& backend, int threads);
  pybind11::dict run(const std::string& out, const pybind11::object& progress, bool resume, bool quiet);
  void close();

 private:
  template <class F>
  auto with(F&& f) const;  // f(Simulation<D>&) of the live simulation; RuntimeError once closed
  void make();

  PyScene scene_;
  std::string backendName_;
  Backend backend_;
  int threads_;
  std::unique_ptr<Simulation<2>> s2_;
  std::unique_ptr<Simulation<3>> s3_;
  PythonVelocity<2>* velocity2_ = nullptr;  // the simulation's source, for set_velocity
  PythonVelocity<3>* velocity3_ = nullptr;
};

}  // namespace morphoflow
