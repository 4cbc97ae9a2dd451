#include "python/py_studio.h"

#include <memory>
#include <optional>

#include <nlohmann/json.hpp>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "scenes/scene_loader.h"
#include "studio/studio_server.h"

namespace py = pybind11;

namespace morphoflow {

namespace {

// A studio served on threads of its own while Python goes on; stop() (or
// leaving a `with` block, or the object going) closes it.
class PyStudio {
 public:
  PyStudio(const std::optional<std::string>& scene, const ServerOptions& server, const StudioOptions& studio) {
    const std::string path = scene.value_or("");
    const std::string text = path.empty() ? std::string() : readSceneText(path);
    py::gil_scoped_release release;
    server_ = std::make_unique<StudioServer>(server, studio, text, path, MORPHOFLOW_SCENE_DIR);
  }
  ~PyStudio() { stop(); }

  const StudioServer& open() const {
    if (!server_) throw std::runtime_error("this studio is stopped");
    return *server_;
  }
  std::string url() const { return open().url(); }
  std::string token() const { return open().token(); }
  int port() const { return open().port(); }
  bool running() const { return server_ != nullptr; }
  // The state /api/state gives, as a dict (None before a scene is open).
  py::object state() const {
    const auto s = open().session();
    return s ? py::module_::import("json").attr("loads")(s->state().dump()) : py::object(py::none());
  }
  // The scene with every edit, as /api/scene gives it (TOML text).
  py::object sceneText() const {
    const auto s = open().session();
    return s ? py::object(py::str(s->sceneText())) : py::object(py::none());
  }
  void stop() {
    py::gil_scoped_release release;  // (the server's threads are joined; none of them calls Python)
    server_.reset();
  }

 private:
  std::unique_ptr<StudioServer> server_;
};

}  // namespace

void bindStudio(py::module_& m, std::function<std::string()> executable) {
  py::class_<PyStudio>(m, "Studio", "A running studio (docs/studio.md): open `url` in a browser.")
      .def_property_readonly("url", &PyStudio::url, "The page's address, with the token.")
      .def_property_readonly("token", &PyStudio::token)
      .def_property_readonly("port", &PyStudio::port)
      .def_property_readonly("running", &PyStudio::running)
      .def("state", &PyStudio::state,
           "The studio's state as /api/state gives it (a dict; None before a scene is open).")
      .def("scene", &PyStudio::sceneText, "The scene with every edit made so far (TOML text), as Save gives it.")
      .def("stop", &PyStudio::stop, "Stops the simulation and the server; the object then only says running = False.")
      .def("__enter__", [](PyStudio& s) -> PyStudio& { return s; })
      .def("__exit__", [](PyStudio& s, const py::args&) { s.stop(); })
      .def("__repr__", [](const PyStudio& s) {
        return s.running() ? "<morphoflow.Studio " + s.url() + ">" : std::string("<morphoflow.Studio stopped>");
      });

  m.def(
      "studio",
      [executable](const std::optional<std::string>& scene, int port, const std::string& listen,
                   const std::string& backend, int threads, const std::string& out) {
        if (port < 0 || port > 65535)
          throw py::value_error("port must be in [0, 65535] (0: any free port), not " + std::to_string(port));
        if (threads < 0)
          throw py::value_error("threads must be 0 (every core) or more, not " + std::to_string(threads));
        if (backend != "serial" && backend != "tbb" && backend != "gpu")
          throw py::value_error("backend must be 'serial', 'tbb' or 'gpu', not '" + backend + "'");
        ServerOptions server;
        server.port = static_cast<unsigned short>(port);
        server.listen = listen;
        StudioOptions studio;
        studio.backend = backend;
        studio.threads = threads;
        studio.out = out;
        studio.executable = executable();
        return std::make_unique<PyStudio>(scene, server, studio);
      },
      py::arg("scene") = py::none(), py::arg("port") = 0, py::arg("listen") = "127.0.0.1", py::arg("backend") = "tbb",
      py::arg("threads") = 0, py::arg("out") = "studio",
      "Serves a scene file in the browser as `morphoflow studio` does, on threads of its own, and returns a Studio "
      "(its `url` holds the token; stop() or a `with` block ends it). Without a scene the page offers the shipped "
      "ones.");
}

}  // namespace morphoflow
