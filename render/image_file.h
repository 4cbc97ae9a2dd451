// Internal to render/: image files through OpenImageIO. An image is encoded
// in memory and written whole by writeFileAtomically (core/output_file.h).
#pragma once

#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

namespace morphoflow {

bool writeImageAtomically(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                          const void* pixels, std::string* error);

// Every channel of the first subimage as float, interleaved, top row first.
// False + message for a missing, unreadable or empty file.
bool readImageFloat(const std::string& path, OIIO::ImageSpec* spec, std::vector<float>* pixels, std::string* error);

}  // namespace morphoflow
