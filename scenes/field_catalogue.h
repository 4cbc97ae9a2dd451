// The catalogue of fields: every field a simulation of a scene offers,
// declared once, with the grid it lives on, its kind, and where its values
// come from (the state, a per-cell formula of the state, or a derived field
// computed from other fields: sim/derived_fields.h). The scene reader checks
// the names a scene gives against it, the simulations answer field() by it,
// and every sink and the Python module ask for its fields by name.
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

struct Scene;

// The names of the fields beside the reaction-diffusion species (whose names
// are the model's, rd/models.h).
namespace fields {
inline const std::string kSpeed = "speed";
inline const std::string kVorticity = "vorticity";
inline const std::string kPressure = "pressure";
inline const std::string kDye = "dye";
inline const std::string kTemperature = "temperature";
inline const std::string kVelocity = "velocity";
inline const std::string kVelocityMac = "velocity_mac";
inline const std::string kObstacle = "obstacle";
inline const std::string kDensity = "density";
inline const std::string kColor = "color";
inline const std::string kHeight = "height";
inline const std::string kActive = "active";
inline const std::string kActiveChemicals = "active_chemicals";
}  // namespace fields

// The grid a field's values are on; every grid spans the scene's domain.
enum class FieldGrid {
  Chemicals,  // the reaction-diffusion layer's cells
  Fluid,      // the fluid's cells
  Faces,      // the fluid's cells + 1 per axis (MAC faces, the last of each row unused)
  Shown,      // the grid of the shown field (output.field)
  Density,  // the chemicals' when output.vdb_density names a species or the pattern shapes the smoke, else the fluid's
};

enum class FieldKind {
  Scalar,
  Vector,  // D components (x, y[, z])
  Colour,  // 3 components, linear RGB in [0, 1]
  Solid,   // 1 inside a solid, 0 in the fluid
  Mask,    // 1 where a condition holds, 0 elsewhere
};

enum class FieldSource {
  State,     // held by the simulation
  Computed,  // a per-cell formula of the state (|u|, curl u, ...)
  Derived,   // computed from other fields by sim/derived_fields.h
};

struct FieldInfo {
  std::string name;
  FieldGrid grid = FieldGrid::Fluid;
  FieldKind kind = FieldKind::Scalar;
  FieldSource source = FieldSource::State;
  std::string what;        // how it is made, for docs and messages
  bool output = false;     // a scalar output.field, output.vdb_fields and output.vdb_density may name
  bool settable = false;   // set_field and [[deposits]] may set it
  bool dumped = false;     // in a field dump (output.fields)
  bool symmetric = false;  // signed around 0 (an automatic range is centred on 0)
};

class FieldCatalogue {
 public:
  // The fields of a simulation of `scene` (its kind: reaction-diffusion,
  // fluid, coupled, or a layer carried by a given velocity).
  explicit FieldCatalogue(const Scene& scene);

  const std::vector<FieldInfo>& all() const { return fields_; }
  // The field named `name`, or null.
  const FieldInfo* find(const std::string& name) const;
  // Every name, in the catalogue's order (species first).
  std::vector<std::string> names() const;
  // The scalar fields an output key may name (species, then the fluid's).
  std::vector<std::string> outputNames() const;
  // The fluid's scalars among them (output.vdb_fields).
  std::vector<std::string> fluidOutputNames() const;
  // The fields set_field and [[deposits]] may set.
  std::vector<std::string> settableNames() const;
  // The fields of a field dump, in order.
  std::vector<std::string> dumpNames() const;
  const std::vector<std::string>& species() const { return species_; }

 private:
  std::vector<std::string> species_;
  std::vector<FieldInfo> fields_;
};

}  // namespace morphoflow
