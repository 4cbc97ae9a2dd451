#include "scenes/field_catalogue.h"

#include "rd/model_registry.h"
#include "scenes/scene.h"

namespace morphoflow {

FieldCatalogue::FieldCatalogue(const Scene& s) {
  using G = FieldGrid;
  using K = FieldKind;
  using S = FieldSource;
  const bool smoke = s.hasFluid && s.fluid.smoke.enabled;
  // A field dump holds the species, or the fluid's scalars without them.
  const bool fluidDumped = !s.rd.enabled;
  if (s.rd.enabled) species_ = findModel(s.rd.settings.model)->info().species;
  for (const std::string& n : species_)
    fields_.push_back({n, G::Chemicals, K::Scalar, S::State, "a reaction-diffusion species", true, true, true});
  if (s.velocity.enabled) {
    fields_.push_back({fields::kSpeed, G::Chemicals, K::Scalar, S::Computed, "|u| of the given velocity"});
    fields_.push_back({fields::kVelocity, G::Chemicals, K::Vector, S::Computed, "the given velocity"});
  } else if (s.hasFluid) {
    fields_.push_back(
        {fields::kSpeed, G::Fluid, K::Scalar, S::Computed, "|u| at cell centres", true, false, fluidDumped});
    fields_.push_back({fields::kVorticity, G::Fluid, K::Scalar, S::Computed, s.dimension == 2 ? "curl u" : "|curl u|",
                       true, false, fluidDumped, s.dimension == 2});
    fields_.push_back(
        {fields::kPressure, G::Fluid, K::Scalar, S::State, "the projection's pressure", true, false, fluidDumped});
    fields_.push_back({fields::kDye, G::Fluid, K::Scalar, S::State, smoke ? "the smoke's density" : "the dye", true,
                       true, fluidDumped});
    fields_.push_back({fields::kTemperature, G::Fluid, K::Scalar, S::State,
                       smoke ? "the smoke's temperature" : "0 (the scene has no [smoke])", smoke, smoke,
                       fluidDumped && smoke});
    fields_.push_back({fields::kVelocity, G::Fluid, K::Vector, S::Computed, "u at cell centres"});
    fields_.push_back({fields::kObstacle, G::Fluid, K::Solid, S::Computed, "1 in solid cells"});
    fields_.push_back({fields::kVelocityMac, G::Faces, K::Vector, S::State,
                       "u on the MAC faces: component a on the faces normal to axis a"});
  }
  fields_.push_back(
      {fields::kDensity, G::Density, K::Scalar, S::Derived,
       "output.vdb_density (a field, or an expression of fields evaluated per cell); a patterned smoke's default: "
       "the smoke shaped by the shown species"});
  fields_.push_back(
      {fields::kColor, G::Shown, K::Colour, S::Derived, "the frames' palette applied to output.field, as linear RGB"});
  fields_.push_back({fields::kHeight, G::Shown, K::Scalar, S::Derived,
                     "output.field mapped to [0, 1] by the frames' range (a normal map's height)"});
  if (smoke) {
    fields_.push_back({fields::kActive, G::Fluid, K::Mask, S::Derived,
                       "1 where the smoke exceeds output.vdb_tolerance (1 everywhere with output.vdb_sparse = false)"});
    if (s.rd.enabled)
      fields_.push_back({fields::kActiveChemicals, G::Chemicals, K::Mask, S::Derived,
                         "active on the chemicals' grid (the smoke sampled at their centres)"});
  }
}

const FieldInfo* FieldCatalogue::find(const std::string& name) const {
  for (const FieldInfo& f : fields_)
    if (f.name == name) return &f;
  return nullptr;
}

namespace {

template <class Keep>
std::vector<std::string> namesWhere(const std::vector<FieldInfo>& all, Keep keep) {
  std::vector<std::string> out;
  for (const FieldInfo& f : all)
    if (keep(f)) out.push_back(f.name);
  return out;
}

}  // namespace

std::vector<std::string> FieldCatalogue::names() const {
  return namesWhere(fields_, [](const FieldInfo&) { return true; });
}

std::vector<std::string> FieldCatalogue::outputNames() const {
  return namesWhere(fields_, [](const FieldInfo& f) { return f.output; });
}

std::vector<std::string> FieldCatalogue::fluidOutputNames() const {
  return namesWhere(fields_, [](const FieldInfo& f) { return f.output && f.grid == FieldGrid::Fluid; });
}

std::vector<std::string> FieldCatalogue::settableNames() const {
  return namesWhere(fields_, [](const FieldInfo& f) { return f.settable; });
}

std::vector<std::string> FieldCatalogue::dumpNames() const {
  return namesWhere(fields_, [](const FieldInfo& f) { return f.dumped; });
}

}  // namespace morphoflow
