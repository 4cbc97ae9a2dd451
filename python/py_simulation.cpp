#include "python/py_simulation.h"

#include <cmath>
#include <fstream>
#include <iostream>


#include "core/parallel.h"
#include "gpu/gl_context.h"
#include "run/checkpoint.h"
#include "run/memory_estimate.h"
#include "run/run_clock.h"
#include "run/run_driver.h"
#include "run/run_log.h"
#include "run/run_options.h"
#include "run/scene_hash.h"
#include "scenes/scene_loader.h"
#include "sim/given_flow_simulation.h"
#include "sim/simulation_factory.h"
#include "sim/steppers.h"

namespace py = pybind11;

namespace morphoflow {

namespace {

template <int D>
std::unique_ptr<Simulation<D>> build(const Scene& scene, Backend backend, PythonVelocity<D>** velocity) {
  if (scene.velocity.python) {
    auto source = std::make_unique<PythonVelocity<D>>();
    *velocity = source.get();
    return std::make_unique<GivenFlowSimulation<D>>(scene, std::move(source));
  }
  auto say = [](const std::string& line) { std::cerr << line << "\n"; };
  return makeSimulation<D>(scene, backend, say, say);
}

// A numpy array of a field's grids (x fastest: the shape reversed), the axis first when there are several.
template <int D>
py::array_t<float> toArray(const std::vector<Grid<float, D>>& grids) {
  std::vector<py::ssize_t> shape;
  if (grids.size() > 1) shape.push_back(py::ssize_t(grids.size()));
  for (int k = D - 1; k >= 0; --k) shape.push_back(grids[0].dims()[k]);
  py::array_t<float> a(shape);
  float* out = a.mutable_data();
  for (const Grid<float, D>& g : grids) out = std::copy(g.values().begin(), g.values().end(), out);
  return a;
}

std::string shapeText(const std::vector<py::ssize_t>& shape) {
  std::string s = "(";
  for (size_t k = 0; k < shape.size(); ++k) s += (k ? ", " : "") + std::to_string(shape[k]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

}  // namespace

PySimulation::PySimulation(const PyScene& scene, const std::string& backend, int threads)
    : scene_(scene), backendName_(backend), threads_(threads) {
  if (backend != "tbb" && backend != "serial" && backend != "gpu")
    throw py::value_error("backend must be 'tbb', 'serial' or 'gpu', not '" + backend + "'");
  if (threads < 0) throw py::value_error("threads must be 0 (every core) or more");
  backend_ = backendNamed(backend);
  Call call(*this, "Simulation");
  make();
}

PySimulation::Call::Call(const PySimulation& sim, const char* what) : sim_(const_cast<PySimulation&>(sim)) {
  {
    std::lock_guard<std::mutex> lk(sim_.calls_->mutex);
    if (sim_.calls_->busy)
      throw std::runtime_error(std::string("this Simulation is in ") + sim_.calls_->busy +
                               "() (on another thread, or this is " + "a callback of that call): one call at a time");
    sim_.calls_->busy = what;
  }
  if (sim_.backend_ != Backend::Gpu) return;
  try {
    GlContext::instance();  // (current on this thread; a GpuError while another thread uses the GPU)
  } catch (...) {
    std::lock_guard<std::mutex> lk(sim_.calls_->mutex);
    sim_.calls_->busy = nullptr;
    throw;
  }
}

PySimulation::Call::~Call() {
  std::lock_guard<std::mutex> lk(sim_.calls_->mutex);
  if (sim_.calls_->closeAfter) sim_.free();
  if (sim_.backend_ == Backend::Gpu) GlContext::instance().release();
  sim_.calls_->busy = nullptr;
}

// The simulation's memory, freed on this thread (a GPU's with the context current here).
void PySimulation::free() {
  s2_.reset();
  s3_.reset();
  velocity2_ = nullptr;
  velocity3_ = nullptr;
  calls_->closeAfter = false;
}

void PySimulation::make() {
  const Scene& s = *scene_.scene;
  checkBackend(s, backend_);
  checkRunFits(s);
  ThreadLimit limit(backend_ == Backend::Serial ? 1 : threads_);
  if (s.dimension == 2)
    s2_ = build<2>(s, backend_, &velocity2_);
  else
    s3_ = build<3>(s, backend_, &velocity3_);
}

template <class F>
auto PySimulation::with(F&& f) const {
  if (s2_) return f(*s2_);
  if (s3_) return f(*s3_);
  throw std::runtime_error("this Simulation was closed: make a new one");
}

void PySimulation::step(long n) {
  Call call(*this, "step");
  if (n < 0) throw py::value_error("step takes n >= 0");
  const TimeSettings t = runTime(*scene_.scene);
  with([&](auto& sim) {
    ThreadLimit limit(backend_ == Backend::Serial ? 1 : threads_);
    for (long k = 0; k < n; ++k) {
      {
        py::gil_scoped_release release;
        sim.step(t.cfl > 0 ? sim.cflTimeStep(t.cfl, t.dt) : t.dt);
      }
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    sim.checkFinite("at step " + std::to_string(sim.steps()));
    return 0;
  });
}

double PySimulation::time() const {
  Call call(*this, "time");
  return with([](auto& sim) { return sim.time(); });
}
long PySimulation::steps() const {
  Call call(*this, "steps");
  return with([](auto& sim) { return sim.steps(); });
}
std::vector<std::string> PySimulation::fieldNames() const {
  Call call(*this, "field_names");
  return with([](auto& sim) { return sim.fieldNames(); });
}

py::array_t<float> PySimulation::field(const std::string& name) const {
  Call call(*this, "field");
  return fieldOf(name);
}

py::array_t<float> PySimulation::fieldOf(const std::string& name) const {
  return with([&](auto& sim) {
    const std::vector<std::string> names = sim.fieldNames();
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      std::string all;
      for (const std::string& f : names) all += (all.empty() ? "" : ", ") + f;
      throw py::value_error("no field '" + name + "': the fields are " + all);
    }
    return toArray(sim.field(name));
  });
}

void PySimulation::setField(const std::string& name, const py::object& values) {
  Call call(*this, "set_field");
  if (!py::isinstance<py::array>(values)) throw py::type_error("set_field takes a numpy array of float32");
  const py::array a = values.cast<py::array>();
  if (!a.dtype().is(py::dtype::of<float>()))
    throw py::type_error("set_field takes float32 values, not " + std::string(py::str(a.dtype())) +
                         " (astype(numpy.float32))");
  const py::array_t<float> now = fieldOf(name);
  std::vector<py::ssize_t> want(now.shape(), now.shape() + now.ndim()), got(a.shape(), a.shape() + a.ndim());
  if (want != got)
    throw py::value_error("the values of '" + name + "' have the shape " + shapeText(got) + ", not " + shapeText(want));
  const py::array_t<float, py::array::c_style> c(a);
  const float* p = c.data();
  for (py::ssize_t i = 0; i < c.size(); ++i)
    if (!std::isfinite(p[i])) throw py::value_error("the values of '" + name + "' hold a NaN or an infinity");
  with([&](auto& sim) {
    constexpr int D = std::remove_reference_t<decltype(sim)>::kDimension;
    IVec<D> dims;
    for (int k = 0; k < D; ++k) dims[k] = int(want[size_t(D - 1 - k)]);
    Grid<float, D> g(dims, 0.0f);
    std::copy(p, p + g.size(), g.values().begin());
    sim.setField(name, g);
    return 0;
  });
}

void PySimulation::setVelocity(py::object velocity) {
  Call call(*this, "set_velocity");
  with([&](auto& sim) {
    constexpr int D = std::remove_reference_t<decltype(sim)>::kDimension;
    PythonVelocity<D>* source = nullptr;
    if constexpr (D == 2) source = velocity2_;
    else source = velocity3_;
    if (!source) throw py::value_error("set_velocity needs a scene whose [velocity] has python = true");
    // Sampled once now into the chemical grid's faces, so a wrong shape or a NaN is said here.
    const RDSettings& rd = scene_.scene->rd.settings;
    IVec<D> cells;
    std::array<bool, D> periodic{};
    for (int k = 0; k < D; ++k)
      cells[k] = rd.resolution[size_t(k)], periodic[size_t(k)] = rd.boundary == RDBoundary::Periodic;
    MacVelocity<D> trial(cells, rd.size[0] / rd.resolution[0], periodic);
    PythonVelocity<D> check;
    check.set(velocity);
    {
      py::gil_scoped_release release;  // (sample takes it)
      check.sample(sim.time(), &trial);
    }
    source->set(std::move(velocity));
    py::gil_scoped_release release;  // (sample takes it)
    static_cast<GivenFlowSimulation<D>&>(sim).velocityChanged();  // (only a python = true scene has a source)
    return 0;
  });
}

void PySimulation::save(const std::string& path) const {
  Call call(*this, "save");
  const Scene& s = *scene_.scene;
  with([&](auto& sim) {
    CheckpointHeader header;
    header.sceneHash = sceneHash(s);
    header.scene = s.resolvedJson;
    header.step = sim.steps();
    header.time = sim.time();
    header.python = CheckpointHeader::PythonScene{scene_.text, scene_.path, scene_.overrides};
    py::gil_scoped_release release;
    writeCheckpointFile(path, header, [&](StateWriter* w) { sim.save(w); });
    return 0;
  });
}

PySimulation PySimulation::load(const std::string& path, const std::string& backend, int threads) {
  Checkpoint c = readCheckpoint(path);
  const CheckpointHeader& h = c.header;
  if (!h.python)
    throw py::value_error(path + ": not a checkpoint of Simulation.save (a run's checkpoints resume with "
                                 "Simulation.run(out, resume=True))");
  PyScene scene;
  scene.text = h.python->text;
  scene.path = h.python->path;
  scene.overrides = h.python->overrides;
  scene.scene = std::make_shared<Scene>(parseScene(scene.text, scene.path, scene.overrides));
  if (sceneHash(*scene.scene) != h.sceneHash)
    throw py::value_error(path + ": the scene reads files that changed since the checkpoint was written");
  PySimulation sim(scene, backend, threads);
  {
    Call call(sim, "load");
    const StateReader state(std::move(c.state));
    sim.with([&](auto& s) {
      s.load(state);
      return 0;
    });
  }
  return sim;
}

py::dict PySimulation::run(const std::string& out, const py::object& progress, bool resume, bool quiet) {
  Call call(*this, "run");
  RunOptions opt;
  opt.scene = scene_.path;
  opt.out = out;
  opt.backend = backendName_;
  opt.threads = threads_;
  opt.quiet = quiet;
  opt.resume = resume;
  RunLog log(quiet, false);
  if (!progress.is_none())
    log.listen([&progress](long frame, long step, long total, double time, double end) {
      py::gil_scoped_acquire gil;
      py::dict d;
      d["frame"] = frame, d["step"] = step, d["total_steps"] = total, d["time"] = time, d["end_time"] = end;
      progress(d);
    });
  const int status = with([&](auto& sim) {
    ThreadLimit limit(backend_ == Backend::Serial ? 1 : threads_);
    py::gil_scoped_release release;
    return driveRun(sim, *scene_.scene, opt, &log);
  });
  if (status == 130 || status == 143) {  // stopped by SIGINT or SIGTERM, with a checkpoint
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  std::ifstream in(std::filesystem::path(out) / "run.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return py::module_::import("json").attr("loads")(text);
}

void PySimulation::close() {
  {
    std::lock_guard<std::mutex> lk(calls_->mutex);
    if (calls_->busy) {
      calls_->closeAfter = true;
      return;
    }
  }
  Call call(*this, "close");
  free();
}

PySimulation::~PySimulation() {
  if (!calls_ || (!s2_ && !s3_)) return;  // (moved from, or closed)
  try {
    Call call(*this, "close");
    free();
  } catch (const std::exception&) {  // the GPU in use on another thread: its memory is left to the process's end
    (void)s2_.release();
    (void)s3_.release();
  }
}

}  // namespace morphoflow
