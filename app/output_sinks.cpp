#include "app/output_sinks.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "render/field_dump.h"
#include "render/field_image.h"
#include "render/image_io.h"

namespace morphoflow {

template <int D>
ImageSink<D>::ImageSink(const std::filesystem::path& out, const Scene& scene) : dir_(out / "frames"), scene_(scene) {
  std::filesystem::create_directories(dir_);
}

template <int D>
void ImageSink<D>::write(long frame, long step, const Simulation<D>& sim) {
  const OutputSettings& o = scene_.output;
  FieldImageOptions io;
  io.palette = o.gradient.empty() ? namedPalette(o.colormap) : Palette{o.gradient};
  io.autoRange = o.autoRange;
  io.symmetric = sim.symmetric(o.field);
  io.range[0] = o.range[0];
  io.range[1] = o.range[1];
  io.slice = o.slice;
  int w, h;
  std::vector<uint8_t> rgb;
  if (o.colormap == kTwoSpeciesPalette) {
    const std::vector<std::string> sp = sim.species();
    rgb = twoFieldsToRgb<D>(sim.field(sp[0]).front(), sim.field(sp[1]).front(), io, &w, &h);
  } else {
    rgb = fieldToRgb<D>(sim.field(o.field).front(), io, &w, &h);
  }
  std::string err;
  const std::filesystem::path file = dir_ / fmt::format("{:06d}.{}", frame, o.format);
  if (!writeRgb8(file.string(), w, h, rgb, &err)) throw std::runtime_error("writing " + file.string() + ": " + err);
  if (firstWritten_ < 0) firstWritten_ = frame;
  ++written_;
}

template <int D>
void ImageSink<D>::finish() {
  if (!scene_.output.video) return;
  VideoRequest r;
  r.frames = dir_;
  r.firstFrame = int(std::max<long>(0, firstWritten_));
  r.frameCount = written_;
  r.fps = scene_.output.fps;
  r.file = dir_.parent_path() / ((scene_.name.empty() ? std::string("animation") : scene_.name) + ".mp4");
  video_ = encodeVideo(r);
  videoDone_ = true;
  videoFile_ = r.file;
}

template <int D>
void ImageSink<D>::report(nlohmann::json* j) const {
  (*j)["frames_written"] = written_;
  if (videoDone_)
    (*j)["video"] = {{"file", videoFile_.string()},
                     {"written", video_.written},
                     {"warning", video_.warning},
                     {"ffmpeg_log", video_.log.string()}};
}

template <int D>
FieldDumpSink<D>::FieldDumpSink(const std::filesystem::path& out) : dir_(out / "fields") {
  std::filesystem::create_directories(dir_);
}

template <int D>
void FieldDumpSink<D>::write(long frame, long step, const Simulation<D>& sim) {
  FieldDump d;
  d.names = sim.dumpFieldNames();
  for (const std::string& n : d.names) d.channels.push_back(sim.field(n).front().values());
  const Grid<float, D> first = sim.field(d.names.front()).front();
  for (int a = 0; a < D; ++a) d.resolution.push_back(first.dim(a));
  d.time = sim.time();
  d.step = step;
  std::string err;
  const std::filesystem::path file = dir_ / fmt::format("{:06d}.exr", frame);
  if (!writeFieldDump(file.string(), d, &err)) throw std::runtime_error("writing " + file.string() + ": " + err);
  ++written_;
}

template <int D>
void FieldDumpSink<D>::report(nlohmann::json* j) const {
  (*j)["fields_written"] = written_;
}

template <int D>
std::vector<std::unique_ptr<OutputSink<D>>> makeOutputSinks(const std::filesystem::path& out, const Scene& scene) {
  std::vector<std::unique_ptr<OutputSink<D>>> sinks;
  if (scene.output.images) sinks.push_back(std::make_unique<ImageSink<D>>(out, scene));
  if (scene.output.fields) sinks.push_back(std::make_unique<FieldDumpSink<D>>(out));
  return sinks;
}

template class ImageSink<2>;
template class ImageSink<3>;
template class FieldDumpSink<2>;
template class FieldDumpSink<3>;
template std::vector<std::unique_ptr<OutputSink<2>>> makeOutputSinks<2>(const std::filesystem::path&, const Scene&);
template std::vector<std::unique_ptr<OutputSink<3>>> makeOutputSinks<3>(const std::filesystem::path&, const Scene&);

}  // namespace morphoflow
