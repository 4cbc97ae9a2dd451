// Internal to render/: image files through OpenImageIO. An image is encoded
// in memory and written whole by writeFileAtomically (core/output_file.h).
#pragma once

#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

namespace morphoflow {

bool writeImageAtomically(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                          const void* pixels, std::string* error);

// The largest image read (its header is checked before decoding).
constexpr int kMaxImageSide = 32768;
constexpr long kMaxImageValues = 1L << 28;  // width x height x channels (1 GiB of floats)

// Every channel of the first subimage as float, interleaved, top row first.
// False + message for a missing, unreadable, empty or oversized file.
bool readImageFloat(const std::string& path, OIIO::ImageSpec* spec, std::vector<float>* pixels, std::string* error);

}  // namespace morphoflow
