#include "app/frame_writer.h"

#include <stdexcept>

#include <fmt/format.h>

#include "render/field_image.h"
#include "render/image_io.h"

namespace morphoflow {

FrameWriter::FrameWriter(const std::filesystem::path& out, const OutputSettings& output, const RunOptions& options)
    : dir_(out / "frames"), output_(output), options_(options) {
  if (output_.images) std::filesystem::create_directories(dir_);
}

long FrameWriter::frameAt(long step) const {
  if (!output_.images || step % output_.every != 0) return -1;
  long frame = step / output_.every;
  if (frame < options_.firstFrame || (options_.lastFrame >= 0 && frame > options_.lastFrame)) return -1;
  return frame;
}

template <int D>
void FrameWriter::write(long frame, const Grid<float, D>& field, bool symmetric) {
  FieldImageOptions io;
  io.colormap = output_.colormap;
  io.autoRange = output_.autoRange;
  io.symmetric = symmetric;
  io.range[0] = output_.range[0];
  io.range[1] = output_.range[1];
  io.slice = output_.slice;
  int w, h;
  std::vector<uint8_t> rgb = fieldToRgb<D>(field, io, &w, &h);
  std::string err;
  std::filesystem::path file = dir_ / fmt::format("{:06d}.png", frame);
  if (!writeRgb8(file.string(), w, h, rgb, &err)) throw std::runtime_error("writing " + file.string() + ": " + err);
  ++written_;
}

template void FrameWriter::write<2>(long, const Grid<float, 2>&, bool);
template void FrameWriter::write<3>(long, const Grid<float, 3>&, bool);

}  // namespace morphoflow
