#include "app/frame_writer.h"

#include <algorithm>
#include <iostream>
#include <stdexcept>

#include <fmt/format.h>

#include "render/field_dump.h"
#include "render/field_image.h"
#include "render/image_io.h"

namespace morphoflow {

FrameWriter::FrameWriter(const std::filesystem::path& out, const OutputSettings& output, const RunOptions& options)
    : dir_(out / "frames"), fieldsDir_(out / "fields"), output_(output), options_(options) {
  if (output_.images) std::filesystem::create_directories(dir_);
  if (output_.fields) std::filesystem::create_directories(fieldsDir_);
}

long FrameWriter::frameAt(long step) const {
  if ((!output_.images && !output_.fields) || step % output_.every != 0) return -1;
  long frame = step / output_.every;
  if (frame < options_.firstFrame || (options_.lastFrame >= 0 && frame > options_.lastFrame)) return -1;
  return frame;
}

template <int D>
void FrameWriter::write(long frame, const Grid<float, D>& field, bool symmetric, const Grid<float, D>* green) {
  if (!output_.images) return;
  FieldImageOptions io;
  io.palette = output_.gradient.empty() ? namedPalette(output_.colormap) : Palette{output_.gradient};
  io.autoRange = output_.autoRange;
  io.symmetric = symmetric;
  io.range[0] = output_.range[0];
  io.range[1] = output_.range[1];
  io.slice = output_.slice;
  int w, h;
  std::vector<uint8_t> rgb = green ? twoFieldsToRgb<D>(field, *green, io, &w, &h) : fieldToRgb<D>(field, io, &w, &h);
  std::string err;
  std::filesystem::path file = dir_ / fmt::format("{:06d}.{}", frame, output_.format);
  if (!writeRgb8(file.string(), w, h, rgb, &err)) throw std::runtime_error("writing " + file.string() + ": " + err);
  if (firstWritten_ < 0) firstWritten_ = frame;
  ++written_;
}

void FrameWriter::finishVideo(const std::string& name) {
  if (!output_.video) return;
  VideoRequest r;
  r.frames = dir_;
  r.firstFrame = int(std::max<long>(0, firstWritten_));
  r.frameCount = written_;
  r.fps = output_.fps;
  r.file = dir_.parent_path() / ((name.empty() ? std::string("animation") : name) + ".mp4");
  video_ = encodeVideo(r);
  videoDone_ = true;
  videoFile_ = r.file;
  if (!video_.written) std::cerr << "warning: " << video_.warning << "\n";
}

template <int D>
void FrameWriter::writeFields(long frame, const std::vector<std::string>& names,
                              const std::vector<Grid<float, D>>& fields, double time, long step) {
  if (!output_.fields) return;
  FieldDump d;
  for (int a = 0; a < D; ++a) d.resolution.push_back(fields.front().dim(a));
  d.names = names;
  for (const Grid<float, D>& g : fields) d.channels.push_back(g.values());
  d.time = time;
  d.step = step;
  std::string err;
  std::filesystem::path file = fieldsDir_ / fmt::format("{:06d}.exr", frame);
  if (!writeFieldDump(file.string(), d, &err)) throw std::runtime_error("writing " + file.string() + ": " + err);
  ++fieldsWritten_;
}

template void FrameWriter::write<2>(long, const Grid<float, 2>&, bool, const Grid<float, 2>*);
template void FrameWriter::write<3>(long, const Grid<float, 3>&, bool, const Grid<float, 3>*);
template void FrameWriter::writeFields<2>(long, const std::vector<std::string>&, const std::vector<Grid<float, 2>>&,
                                          double, long);
template void FrameWriter::writeFields<3>(long, const std::vector<std::string>&, const std::vector<Grid<float, 3>>&,
                                          double, long);

}  // namespace morphoflow
