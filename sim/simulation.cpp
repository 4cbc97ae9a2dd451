#include "sim/simulation.h"

#include "sim/derived_fields.h"

namespace morphoflow {

template <int D>
std::vector<Grid<float, D>> Simulation<D>::field(const std::string& name) const {
  const FieldCatalogue catalogue = fields();
  const FieldInfo* f = catalogue.find(name);
  if (f && f->source == FieldSource::Derived) return derivedField<D>(*this, name);
  return ownField(name);
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace morphoflow
