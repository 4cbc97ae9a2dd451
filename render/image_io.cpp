#include "render/image_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "core/output_file.h"

#include "render/image_file.h"

namespace morphoflow {

bool readImageFloat(const std::string& path, OIIO::ImageSpec* spec, std::vector<float>* pixels, std::string* error) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    *error = "no such file: " + path;
    return false;
  }
  if (!std::filesystem::is_regular_file(path, ec)) {
    *error = "not a regular file (a folder, device or pipe): " + path;
    return false;
  }
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    *error = OIIO::geterror();
    return false;
  }
  *spec = in->spec();
  if (spec->width <= 0 || spec->height <= 0 || spec->nchannels <= 0 || spec->depth != 1) {
    *error = "empty image (or a volume): " + path;
    return false;
  }
  // The header's size is checked before anything is decoded: a small file
  // may claim 100000 x 100000 pixels.
  const double values = double(spec->width) * double(spec->height) * double(spec->nchannels);
  if (spec->width > kMaxImageSide || spec->height > kMaxImageSide || values > double(kMaxImageValues)) {
    *error = path + " claims " + std::to_string(spec->width) + " x " + std::to_string(spec->height) + " pixels, " +
             std::to_string(spec->nchannels) + " channels: more than this program reads (" +
             std::to_string(kMaxImageSide) + " pixels a side, " + std::to_string(kMaxImageValues >> 20) + " Mi values)";
    return false;
  }
  pixels->resize(size_t(spec->width) * size_t(spec->height) * size_t(spec->nchannels));
  if (!in->read_image(0, 0, 0, spec->nchannels, OIIO::TypeDesc::FLOAT, pixels->data())) {
    *error = in->geterror();
    return false;
  }
  return true;
}

bool readGrayImage(const std::string& path, GrayImage* image, std::string* error) {
  OIIO::ImageSpec spec;
  std::vector<float> all;
  if (!readImageFloat(path, &spec, &all, error)) return false;
  image->width = spec.width;
  image->height = spec.height;
  image->pixels.resize(size_t(spec.width) * size_t(spec.height));
  const int nc = spec.nchannels;
  for (size_t i = 0; i < image->pixels.size(); ++i) {
    const float* p = &all[i * size_t(nc)];
    // Luminance for colour images, the channel itself otherwise.
    image->pixels[i] = nc >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
  }
  return true;
}

bool readRgb8(const std::string& path, int* width, int* height, std::vector<uint8_t>* rgb, std::string* error) {
  OIIO::ImageSpec spec;
  std::vector<float> all;
  if (!readImageFloat(path, &spec, &all, error)) return false;
  *width = spec.width;
  *height = spec.height;
  const size_t n = size_t(spec.width) * size_t(spec.height), nc = size_t(spec.nchannels);
  rgb->resize(n * 3);
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 0; k < 3; ++k)
      (*rgb)[i * 3 + k] = uint8_t(std::lround(255.0f * std::clamp(all[i * nc + std::min(k, nc - 1)], 0.0f, 1.0f)));
  return true;
}

bool writeImageAtomically(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                          const void* pixels, std::string* error) {
  // Encoded in memory, then written by the one checked writer (a full disk
  // or a missing permission is an OutputError naming the path).
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput memory(bytes);
  auto out = OIIO::ImageOutput::create(path, &memory);
  if (!out) {
    *error = "no image writer for " + path + ": " + OIIO::geterror();
    return false;
  }
  // No write time in the file (OpenImageIO stamps one otherwise): the same
  // fields give the same bytes, in a rerun or a resumed run.
  OIIO::ImageSpec stamped = spec;
  stamped.attribute("DateTime", "");
  if (!out->open(path, stamped) || !out->write_image(type, pixels) || !out->close()) {
    *error = out->geterror();
    return false;
  }
  writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  return true;
}

bool writeRgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb,
               std::string* error) {
  // EXR frames store the palette colours as half floats in [0, 1]; other formats as 8 bits.
  if (std::filesystem::path(path).extension() == ".exr") {
    std::vector<float> f(rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i) f[i] = float(rgb[i]) / 255.0f;
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::HALF);
    return writeImageAtomically(path, spec, OIIO::TypeDesc::FLOAT, f.data(), error);
  }
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  return writeImageAtomically(path, spec, OIIO::TypeDesc::UINT8, rgb.data(), error);
}

}  // namespace morphoflow
