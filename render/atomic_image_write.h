// Internal to render/: writes an image through OpenImageIO to a temporary
// name, then renames it, so a crash never leaves a half-written file.
#pragma once

#include <string>

#include <OpenImageIO/imageio.h>

namespace morphoflow {

bool writeImageAtomically(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                          const void* pixels, std::string* error);

}  // namespace morphoflow
