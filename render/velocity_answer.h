// A given velocity volume as the VDB reader's answer (render/vdb_read_here.h)
// carries it to the process that asked: ok, then the error or the volume,
// field by field. No OpenVDB here: both sides use it.
#pragma once

#include <string>

#include "render/vdb_volume.h"

namespace morphoflow {

std::string encodeVelocityAnswer(bool ok, const VelocityVolume& v, const std::string& error);
// False and *error the reader's error, or a note that the answer is cut short.
bool decodeVelocityAnswer(const std::string& s, VelocityVolume* v, std::string* error);

}  // namespace morphoflow
