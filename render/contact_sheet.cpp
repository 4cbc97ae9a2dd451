#include "render/contact_sheet.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "core/output_file.h"
#include "render/image_file.h"

namespace morphoflow {

namespace {

constexpr int kPad = 6, kLabel = 22, kFontSize = 14;
const char* const kFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

// A frame as RGB, scaled to `width` pixels across (and at most 4 widths
// down); an uninitialised buffer and *error when it cannot be read.
OIIO::ImageBuf scaledFrame(const std::string& path, int width, std::string* error) {
  OIIO::ImageSpec spec;
  std::vector<float> px;
  if (!readImageFloat(path, &spec, &px, error)) return {};
  OIIO::ImageSpec rgbSpec(spec.width, spec.height, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf rgb(rgbSpec);
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const float* p = &px[(size_t(y) * size_t(spec.width) + size_t(x)) * size_t(spec.nchannels)];
      const float c[3] = {p[0], p[spec.nchannels >= 3 ? 1 : 0], p[spec.nchannels >= 3 ? 2 : 0]};
      rgb.setpixel(x, y, c, 3);
    }
  const double scale = std::min(double(width) / spec.width, 4.0 * width / spec.height);
  const int w = std::max(1, int(scale * spec.width + 0.5)), h = std::max(1, int(scale * spec.height + 0.5));
  return OIIO::ImageBufAlgo::resize(rgb, "", 0.0f, OIIO::ROI(0, w, 0, h, 0, 1, 0, 3));
}

void label(OIIO::ImageBuf* sheet, int x, int y, const std::string& text) {
  static const bool haveFont = std::filesystem::exists(kFont);
  const float black[3] = {0.05f, 0.05f, 0.05f};
  OIIO::ImageBufAlgo::render_text(*sheet, x, y, text, kFontSize, haveFont ? kFont : "", black);
}

}  // namespace

std::vector<std::string> writeContactSheet(const std::string& path, const ContactSheet& s) {
  const size_t nc = s.columns.size(), nr = s.rows.size();
  if (nc == 0 || nr == 0 || s.images.size() != nc * nr) throw std::logic_error("contact sheet: no cells");
  std::vector<OIIO::ImageBuf> frames(s.images.size());
  std::vector<std::string> unread;
  int cellH = 0;
  for (size_t i = 0; i < s.images.size(); ++i)
    if (!s.images[i].empty()) {
      std::string error;
      frames[i] = scaledFrame(s.images[i], s.cellWidth, &error);
      if (!frames[i].initialized()) unread.push_back(s.images[i] + ": " + error);
      else cellH = std::max(cellH, frames[i].spec().height);
    }
  if (cellH == 0) cellH = s.cellWidth;
  int rowLabelW = 0;
  for (const std::string& r : s.rows) rowLabelW = std::max(rowLabelW, int(r.size()) * kFontSize * 6 / 10 + 2 * kPad);
  const int left = rowLabelW, top = 2 * kLabel;
  const int width = left + int(nc) * (s.cellWidth + kPad) + kPad, height = top + int(nr) * (cellH + kPad) + kPad;
  OIIO::ImageBuf sheet(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT));
  const float white[3] = {1, 1, 1}, grey[3] = {0.8f, 0.8f, 0.8f};
  OIIO::ImageBufAlgo::fill(sheet, white);
  label(&sheet, kPad, kLabel - 6, s.title);
  for (size_t c = 0; c < nc; ++c) label(&sheet, left + int(c) * (s.cellWidth + kPad), top - 6, s.columns[c]);
  for (size_t r = 0; r < nr; ++r) {
    const int y0 = top + int(r) * (cellH + kPad);
    label(&sheet, kPad, y0 + cellH / 2, s.rows[r]);
    for (size_t c = 0; c < nc; ++c) {
      const int x0 = left + int(c) * (s.cellWidth + kPad);
      const OIIO::ImageBuf& f = frames[r * nc + c];
      if (f.initialized()) OIIO::ImageBufAlgo::paste(sheet, x0, y0, 0, 0, f);
      else OIIO::ImageBufAlgo::fill(sheet, grey, OIIO::ROI(x0, x0 + s.cellWidth, y0, y0 + cellH, 0, 1, 0, 3));
    }
  }
  std::vector<unsigned char> rgb(size_t(width) * size_t(height) * 3);
  sheet.get_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, 3), OIIO::TypeDesc::UINT8, rgb.data());
  std::string error;
  if (!writeImageAtomically(path, OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::UINT8), OIIO::TypeDesc::UINT8,
                            rgb.data(), &error))
    throw OutputError(path, "the contact sheet cannot be written: " + error);
  return unread;
}

}  // namespace morphoflow
