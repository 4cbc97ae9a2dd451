// Simulation<D>: what the run driver (run/run_driver.h) needs of any
// simulation, fluid-only, reaction-diffusion-only or coupled, on any backend:
// advance one step, say where it is, expose named output fields, and save and
// restore its complete state. The driver owns everything else: the frame
// schedule, outputs, progress, checkpoints and run.json.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/grid.h"
#include "core/state_archive.h"
#include "scenes/field_catalogue.h"
#include "scenes/scene.h"

namespace morphoflow {

template <int D>
class Simulation {
 public:
  static constexpr int kDimension = D;
  virtual ~Simulation() = default;

  // Advances one step of dt.
  virtual void step(double dt) = 0;
  // Advances `count` steps of dt, bitwise as `count` calls of step(dt).
  virtual void advance(double dt, long count) {
    for (long k = 0; k < count; ++k) step(dt);
  }
  // How many steps advance() takes faster together than one at a time (1:
  // none; the fused explicit RD step's temporal blocking takes several).
  virtual long stepsTogether() const { return 1; }
  // The largest dt with |u|max dt <= cfl h (dtMax when nothing moves).
  virtual double cflTimeStep(double cfl, double dtMax) const { return dtMax; }
  virtual double time() const = 0;
  virtual long steps() const = 0;

  // The scene it runs: its fields' catalogue (scenes/field_catalogue.h) and
  // the settings of its derived fields.
  virtual const Scene& scene() const = 0;
  FieldCatalogue fields() const { return FieldCatalogue(scene()); }
  // Every field field() can return, in the catalogue's order.
  std::vector<std::string> fieldNames() const { return fields().names(); }
  // The reaction-diffusion species (empty without a layer).
  virtual std::vector<std::string> species() const { return {}; }
  // The fields a field dump holds, in order.
  std::vector<std::string> dumpFieldNames() const { return fields().dumpNames(); }
  // A named field of the catalogue: one grid, or D (x, y[, z]) for a
  // vector, 3 for a colour. Each field is on its own grid (species on the RD
  // grid, the rest on the fluid's); all of them span the same domain. A
  // derived field is computed from the others (sim/derived_fields.h).
  std::vector<Grid<float, D>> field(const std::string& name) const;
  // Sets a field from values on its grid (field()'s shape): a species, the
  // dye (the smoke) or the temperature; throws UserError (key "set_field")
  // for a field computed from the state (speed, vorticity, ...) or one this
  // simulation lacks. A NaN leaves its cell as it is (a brush's footprint).
  virtual void setField(const std::string& name, const Grid<float, D>& values) {
    throw UserError({"set_field", 0, 0}, "", "the field '" + name + "' cannot be set",
                    "set_field takes a species, dye or temperature");
  }

  // Whether the field is signed around 0 (an automatic image range is then
  // centred on 0).
  bool symmetric(const std::string& name) const {
    const FieldCatalogue catalogue = fields();
    const FieldInfo* f = catalogue.find(name);
    return f && f->symmetric;
  }
  // Whether the scene has solid cells (the "obstacle" field is then nonzero
  // inside them).
  virtual bool hasObstacles() const { return false; }

  // Files of the simulation's own measurements (probes), written at the
  // end: a path relative to the output folder, and the text.
  virtual std::vector<std::pair<std::string, std::string>> measurementFiles() const { return {}; }

  // Throws std::runtime_error when the state is no longer finite; `when`
  // says when ("at step 12").
  virtual void checkFinite(const std::string& when) const {}

  // Everything step() depends on, so that load(save()) continues bit for bit.
  virtual void save(StateWriter* out) const = 0;
  virtual void load(const StateReader& in) = 0;

  // run.json: "resolved" values of the scene, and the simulation's own
  // statistics (solver iterations, stage times) under their own keys.
  virtual nlohmann::json resolved() const = 0;
  virtual void report(nlohmann::json* run) const = 0;

 protected:
  // A field the simulation holds or computes per cell (not a derived one).
  virtual std::vector<Grid<float, D>> ownField(const std::string& name) const = 0;
};

}  // namespace morphoflow
