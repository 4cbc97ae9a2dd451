// The Python module's Scene and Simulation: a scene kept alive with the
// text it came from (for checkpoints), and a Simulation<2> or <3> on a
// backend, with the GIL released while it steps.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "sim/simulation.h"
#include "python/python_velocity.h"
#include "scenes/scene.h"
#include "core/backend.h"

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
  // Frees the simulation now, or when the call in progress (on another
  // thread, or the one whose callback closes it) ends.
  void close();
  ~PySimulation();
  PySimulation(PySimulation&&) = default;

 private:
  // One call at a time, refused (RuntimeError naming the call in progress),
  // never interleaved: a call from another thread, or from a callback of the
  // call in progress. On the GPU backend the call holds the GL context on
  // its thread and lets it go at its end.
  struct Calls {
    std::mutex mutex;
    const char* busy = nullptr;
    bool closeAfter = false;
  };
  class Call {
   public:
    Call(const PySimulation& sim, const char* what);
    ~Call();
    Call(const Call&) = delete;
    Call& operator=(const Call&) = delete;

   private:
    PySimulation& sim_;
  };
  void free();

  template <class F>
  auto with(F&& f) const;  // f(Simulation<D>&) of the live simulation; RuntimeError once closed
  void make();
  pybind11::array_t<float> fieldOf(const std::string& name) const;

  PyScene scene_;
  std::string backendName_;
  Backend backend_;
  int threads_;
  std::unique_ptr<Simulation<2>> s2_;
  std::unique_ptr<Simulation<3>> s3_;
  PythonVelocity<2>* velocity2_ = nullptr;  // the simulation's source, for set_velocity
  PythonVelocity<3>* velocity3_ = nullptr;
  std::shared_ptr<Calls> calls_ = std::make_shared<Calls>();
};

}  // namespace morphoflow
