// How the frames colour a field: output.colormap or output.gradient over
// output.range, or over the field's own range (centred on 0 for a signed
// field). The image sink, the colour and height fields and the studio use it.
#pragma once

#include <string>
#include <vector>

#include "render/field_image.h"
#include "scenes/scene.h"

namespace morphoflow {

inline FieldImageOptions frameImageOptions(const OutputSettings& o, bool symmetric) {
  FieldImageOptions io;
  io.palette = o.gradient.empty() ? namedPalette(o.colormap) : Palette{o.gradient};
  io.autoRange = o.autoRange;
  io.symmetric = symmetric;
  io.range[0] = o.range[0];
  io.range[1] = o.range[1];
  io.slice = o.slice;
  return io;
}

// The field the frames show: output.field, or the first species under the
// two-species palette (the second is drawn beside it).
inline std::string shownField(const OutputSettings& o, const std::vector<std::string>& species) {
  return o.colormap == kTwoSpeciesPalette && !species.empty() ? species.front() : o.field;
}

}  // namespace morphoflow
