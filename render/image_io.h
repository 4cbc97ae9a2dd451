// Image files through OpenImageIO. Only render/ includes OpenImageIO.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace morphoflow {

struct GrayImage {
  int width = 0, height = 0;
  std::vector<float> pixels;  // row-major, top row first; first channel (or luminance)
};

// Reads any image OpenImageIO knows (PNG, EXR, TIFF, ...). False + message on failure.
bool readGrayImage(const std::string& path, GrayImage* image, std::string* error);

// Reads an image's first three channels as 8-bit RGB (row-major, top row
// first; a gray image's one channel in all three). False + message on failure.
bool readRgb8(const std::string& path, int* width, int* height, std::vector<uint8_t>* rgb, std::string* error);

// Writes 8-bit RGB (row-major, top row first): 8-bit files (PNG), or half-float
// RGB in [0, 1] when the path ends in .exr. The image is encoded in memory and
// written whole through writeFileAtomically (core/output_file.h): a failed
// write throws OutputError naming the path, and leaves no file cut short.
bool writeRgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb,
               std::string* error);

}  // namespace morphoflow
