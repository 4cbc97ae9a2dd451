// Float field dumps: every species of a reaction-diffusion state as one
// OpenEXR file with one full-precision float channel per species, named as the
// model names them (`u`, `v`, ...). 2D grids are an nx x ny image; 3D grids are
// an atlas of z slices stacked top to bottom (nx x ny*nz, slice 0 first).
// Within a slice the top image row is the grid's last row (y up), as in frames.
// The grid shape, time and step travel as metadata (morphoflow:resolution,
// morphoflow:time, morphoflow:step).
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

struct FieldDump {
  std::vector<int> resolution;               // [nx, ny] or [nx, ny, nz]
  std::vector<std::string> names;            // one per channel
  std::vector<std::vector<float>> channels;  // grid order, x fastest
  double time = 0.0;
  long step = 0;
};

// Written whole through writeFileAtomically (core/output_file.h): a failed
// write throws OutputError naming the path. False + message when it cannot be encoded.
bool writeFieldDump(const std::string& path, const FieldDump& dump, std::string* error);

// Reads a dump written by writeFieldDump, or any image: then a 2D grid whose
// channels are the image's (row order turned back to y up).
bool readFieldDump(const std::string& path, FieldDump* dump, std::string* error);

}  // namespace morphoflow
