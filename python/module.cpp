// The Python module `morphoflow` (docs/python.md): scenes, simulations on
// every backend, their fields as numpy arrays, the run loop, batches and
// sweeps, over the same libraries as the command line. Errors are Python
// exceptions: a scene's, with its file:line:column, a ValueError.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdlib>

#include <fstream>
#include <memory>

#include "batch/batch.h"
#include "batch/batch_summary.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/state_archive.h"
#include "python/py_simulation.h"
#include "python/py_studio.h"
#include "scenes/override_text.h"
#include "scenes/scene_loader.h"

namespace py = pybind11;
using namespace morphoflow;

namespace {

// A Python value as TOML text (an override's value).
std::string tomlValue(const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v)) return py::str(py::repr(v));
  if (py::isinstance<py::str>(v)) return tomlString(v.cast<std::string>());
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    std::string s = "[";
    for (const py::handle& item : v) s += (s.size() > 1 ? "," : "") + tomlValue(item);
    return s + "]";
  }
  throw py::type_error("an override's value must be a bool, number, string or list, not " +
                       std::string(py::str(v.get_type().attr("__name__"))));
}

// {"fluid.reynolds": 400} as ["fluid.reynolds=400"].
std::vector<std::string> overrides(const py::object& set) {
  std::vector<std::string> out;
  if (set.is_none()) return out;
  if (!py::isinstance<py::dict>(set)) throw py::type_error("set= takes a dict of dotted keys to values");
  for (const auto& [key, value] : set.cast<py::dict>()) {
    const std::string k = py::str(key).cast<std::string>();
    // A dotted key of bare names (what --set takes): '=', spaces or a newline would set another key.
    if (!isDottedKey(k))
      throw py::value_error("set= takes dotted keys of letters, digits, '_' and '-' (as 'fluid.reynolds'), not '" + k +
                            "'");
    out.push_back(k + "=" + tomlValue(value));
  }
  return out;
}

PyScene sceneFrom(std::string text, std::string path, std::vector<std::string> sets) {
  PyScene s;
  s.scene = std::make_shared<Scene>(parseScene(text, path, sets));
  s.text = std::move(text);
  s.path = std::move(path);
  s.overrides = std::move(sets);
  return s;
}

// The summary a batch or sweep wrote into `out`, with its exit status.
py::dict batchResult(int status, const std::string& out) {
  if (status == 130 || status == 143) {  // Ctrl-C (or SIGTERM): the runs checkpointed; resume=True goes on
    PyErr_SetString(PyExc_KeyboardInterrupt,
                    ("the batch in " + out + " stopped; its runs checkpointed (resume=True goes on)").c_str());
    throw py::error_already_set();
  }
  py::dict r;
  r["status"] = status;
  std::ifstream in(summaryPath(out, ""));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  r["summary"] = text.empty() ? py::object(py::none()) : py::module_::import("json").attr("loads")(text);
  return r;
}

// The morphoflow executable the batch's runs use: $MORPHOFLOW_EXECUTABLE, or the one built beside this module.
std::string executable() {
  if (const char* e = std::getenv("MORPHOFLOW_EXECUTABLE")) return e;
  return MORPHOFLOW_EXECUTABLE;
}

BatchOptions batchOptions(const std::string& out, int jobs, const py::object& set, bool keepGoing, bool resume,
                          bool quiet) {
  if (jobs < 1 || jobs > 256)
    throw py::value_error("jobs must be in [1, 256] (as --jobs), not " + std::to_string(jobs));
  if (out.empty()) throw py::value_error("out must name a folder, not ''");
  BatchOptions o;
  o.out = out;
  o.jobs = jobs;
  o.sets = overrides(set);
  o.keepGoing = keepGoing;
  o.resume = resume;
  o.quiet = quiet;
  o.executable = executable();
  return o;
}

}  // namespace

PYBIND11_MODULE(morphoflow, m) {
  m.doc() = "morphoflow: stable fluids carrying reaction-diffusion patterns (docs/python.md)";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const DivergedError& e) {  // (before UserError, its base)
      PyErr_SetString(PyExc_FloatingPointError, e.what());
    } catch (const UserError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const NonFiniteError& e) {
      PyErr_SetString(PyExc_FloatingPointError, (std::string(e.what()) + " (" + e.hint() + ")").c_str());
    } catch (const StateError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  py::class_<PyScene>(m, "Scene", "A scene, parsed and checked as `morphoflow validate` checks it.")
      .def_property_readonly("path", [](const PyScene& s) { return s.path; })
      .def_property_readonly("name", [](const PyScene& s) { return s.scene->name; })
      .def_property_readonly("dimension", [](const PyScene& s) { return s.scene->dimension; })
      .def_property_readonly(
          "settings", [](const PyScene& s) { return py::module_::import("json").attr("loads")(s.scene->resolvedJson); },
          "The scene's resolved settings, as run.json records them (a dict).")
      .def("__repr__",
           [](const PyScene& s) { return "<morphoflow.Scene '" + s.scene->name + "' from " + s.path + ">"; });

  m.def(
      "load_scene",
      [](const std::string& path, const py::object& set) {
        return sceneFrom(readSceneText(path), path, overrides(set));
      },
      py::arg("path"), py::arg("set") = py::none(),
      "Reads a scene file; set={'fluid.reynolds': 400} overrides keys as --set does. A bad scene raises "
      "ValueError naming file:line:column.");
  m.def("scene_from_toml", [](const std::string& text, const std::string& path, const py::object& set) {
          return sceneFrom(text, path, overrides(set));
        },
        py::arg("text"), py::arg("path") = "<string>", py::arg("set") = py::none(),
        "A scene from TOML text; `path` names it in errors and is where its relative file paths start.");

  py::class_<PySimulation>(m, "Simulation", "A scene's simulation on a backend (tbb, serial or gpu).")
      .def(py::init<const PyScene&, const std::string&, int>(), py::arg("scene"), py::arg("backend") = "tbb",
           py::arg("threads") = 0)
      .def("step", &PySimulation::step, py::arg("n") = 1,
           "Takes n steps of the scene's time step (time.dt, shortened to time.cfl where the scene has one); "
           "releases the GIL; Ctrl-C between steps raises KeyboardInterrupt.")
      .def_property_readonly("time", &PySimulation::time)
      .def_property_readonly("steps", &PySimulation::steps)
      .def_property_readonly("field_names", &PySimulation::fieldNames)
      .def("field", &PySimulation::field, py::arg("name"),
           "A field as a new float32 numpy array (a copy), indexed [y, x] or [z, y, x]; 'velocity' has the axis first.")
      .def("set_field", &PySimulation::setField, py::arg("name"), py::arg("values"),
           "Sets a species, the dye (the smoke) or the temperature from a float32 array of field()'s shape.")
      .def("set_velocity", &PySimulation::setVelocity, py::arg("velocity"),
           "For a scene with [velocity] python = true: a callable f(x, y[, z], t) -> (u, v[, w]) of arrays, "
           "a (D, ...) array at the cell centres, or one array per component on its faces.")
      .def("save", &PySimulation::save, py::arg("path"), "Writes the whole state into a checkpoint file.")
      .def_static("load", &PySimulation::load, py::arg("path"), py::arg("backend") = "tbb", py::arg("threads") = 0,
                  "A simulation from a checkpoint file Simulation.save wrote.")
      .def("run", &PySimulation::run, py::arg("out"), py::arg("progress") = py::none(), py::arg("resume") = false,
           py::arg("quiet") = true,
           "Runs the scene to its end through the command line's run loop (frames, VDB volumes, checkpoints, "
           "run.json in `out`); progress(dict) is called after each step. Returns run.json as a dict.")
      .def("close", &PySimulation::close, "Releases the simulation; using it afterwards raises RuntimeError.")
      .def("__enter__", [](PySimulation& s) -> PySimulation& { return s; })
      .def("__exit__", [](PySimulation& s, const py::args&) { s.close(); });

  m.def("batch", [](const std::vector<std::string>& scenes, const std::string& out, int jobs, const py::object& set,
                    bool keepGoing, bool resume, bool quiet) {
          BatchOptions o = batchOptions(out, jobs, set, keepGoing, resume, quiet);
          o.scenes = scenes;
          int status = 0;
          {
            py::gil_scoped_release release;
            status = runBatch(o);
          }
          return batchResult(status, out);
        },
        py::arg("scenes"), py::arg("out") = "out", py::arg("jobs") = 1, py::arg("set") = py::none(),
        py::arg("keep_going") = false, py::arg("resume") = false, py::arg("quiet") = true,
        "Runs scene files as `morphoflow batch` does (each in its own process); returns {'status', 'summary'}.");
  m.def("sweep", [](const std::string& scene, const std::vector<std::string>& vary, const std::string& out, int jobs,
                    const py::object& set, bool resume, bool quiet) {
          BatchOptions o = batchOptions(out, jobs, set, false, resume, quiet);
          o.scenes = {scene};
          o.varies = vary;
          int status = 0;
          {
            py::gil_scoped_release release;
            status = runSweep(o);
          }
          return batchResult(status, out);
        },
        py::arg("scene"), py::arg("vary"), py::arg("out") = "out", py::arg("jobs") = 1, py::arg("set") = py::none(),
        py::arg("resume") = false, py::arg("quiet") = true,
        "Varies a scene's keys as `morphoflow sweep` does (vary=['rd.parameters.F=0.02:0.05:4']); returns "
        "{'status', 'summary'}.");
  bindStudio(m, executable);
}
