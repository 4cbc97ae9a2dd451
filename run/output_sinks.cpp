#include "run/output_sinks.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "core/output_file.h"
#include "fluid/obstacle_motion.h"
#include "render/field_dump.h"
#include "render/field_image.h"
#include "render/image_io.h"
#include "render/lit_volume.h"
#include "render/normal_map.h"
#include "render/volume_preview.h"
#include "run/output_kinds.h"
#include "run/vdb_sink.h"
#include "scenes/field_catalogue.h"
#include "sim/frame_palette.h"

namespace morphoflow {

std::filesystem::path endFile(const std::filesystem::path& dir, const std::string& extension, bool last) {
  std::filesystem::path found;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= extension.size() ||
        name.compare(name.size() - extension.size(), extension.size(), extension) != 0)
      continue;
    if (found.empty() || (last ? e.path() > found : e.path() < found)) found = e.path();
  }
  return found;
}

uintmax_t fileBytes(const std::filesystem::path& file) {
  std::error_code ec;
  const uintmax_t n = std::filesystem::file_size(file, ec);
  return ec ? 0 : n;
}

void addBytes(nlohmann::json* run, const std::string& kind, uintmax_t bytes) {
  nlohmann::json& b = (*run)["bytes_written"];
  b[kind] = (b.contains(kind) ? b[kind].get<uintmax_t>() : 0) + bytes;
}

template <int D>
ImageSink<D>::ImageSink(const std::filesystem::path& out, const Scene& scene)
    : dir_(out / kFrameFiles.folder), scene_(scene) {
  createOutputFolder(dir_);
}

namespace {

// The lit volume of the `density` the VDB frames hold, coloured by the shown
// field, glowing by the smoke's temperature (output.emission).
std::vector<uint8_t> litPreview(const Simulation<3>& sim, const Grid<float, 3>& shown, const FieldImageOptions& io) {
  const Scene& scene = sim.scene();
  const Grid<float, 3> density = sim.field(fields::kDensity).front();
  Grid<float, 3> temperature;
  LitVolume v;
  v.density = &density;
  v.shown = &shown;
  v.options = io;
  Grid<float, 3> solid;
  if (!scene.fluid.obstacles.empty()) {  // where they are now, their own smooth surface
    const FluidSettings& f = scene.fluid;
    std::vector<ObstacleSpec> placed;
    for (size_t q = 0; q < f.obstacles.size(); ++q) {
      if (q < scene.timeline.obstacles.size() && !scene.timeline.obstacles[q].contains(sim.time())) continue;
      placed.push_back(placedAt(f.obstacles[q], 3, sim.time(), nullptr));
      for (int a = 0; a < 3; ++a) placed.back().wrap[size_t(a)] = f.boundaries.periodic(a);
    }
    const IVec<3> cells{f.resolution[0], f.resolution[1], f.resolution[2]};
    solid = solidOccupancy<3>(placed, cells, f.size[0] / f.resolution[0]);
    v.solid = &solid;
  }
  if (scene.output.emission > 0) {
    temperature = sim.field(fields::kTemperature).front();
    v.temperature = &temperature;
    v.ambientTemperature = scene.fluid.smoke.ambient;
    v.emission = scene.output.emission;
  }
  return renderLitVolume(v, scene.output.imageSize).rgb;
}

}  // namespace

template <int D>
void ImageSink<D>::write(const FrameInfo& at, const Simulation<D>& sim) {
  const long frame = at.frame;
  const OutputSettings& o = scene_.output;
  const FieldImageOptions io = frameImageOptions(o, sim.symmetric(o.field));
  int w = 0, h = 0;
  std::vector<uint8_t> rgb;
  const bool two = o.colormap == kTwoSpeciesPalette;
  const std::vector<std::string> sp = sim.species();
  const Grid<float, D> shown = sim.field(shownField(o, sp)).front();
  if (!o.autoRange) {  // 8-bit colours of a fixed range: what lies beyond it is drawn at its ends, and counted
    clipped_ += countOutside(shown.data(), shown.size(), o.range[0], o.range[1]);
    cells_ += shown.size();
  }
  if constexpr (D == 3) {
    // A smoke element is lit; a field that fills its box is seen inside and out.
    const bool element = scene_.hasFluid && scene_.fluid.smoke.enabled && !two;
    if (o.view == "volume" && element) {
      rgb = litPreview(sim, shown, io);
      w = h = o.imageSize;
    } else if (o.view == "volume") {
      rgb = two ? volumeTwoToRgb(shown, sim.field(sp[1]).front(), io, o.imageSize, &w, &h)
                : volumeToRgb(shown, io, o.imageSize, &w, &h);
    }
  }
  if (rgb.empty()) {
    rgb = two ? twoFieldsToRgb<D>(shown, sim.field(sp[1]).front(), io, &w, &h) : fieldToRgb<D>(shown, io, &w, &h);
    rgb = upscaleToWidth(rgb, &w, &h, o.imageSize);
  }
  std::string err;
  const std::filesystem::path file = dir_ / fmt::format("{:06d}.{}", frame, o.format);
  if (!writeRgb8(file.string(), w, h, rgb, &err)) throw std::runtime_error("writing " + file.string() + ": " + err);
  if (firstWritten_ < 0) firstWritten_ = frame;
  ++written_;
  bytes_ += fileBytes(file);
}

template <int D>
void ImageSink<D>::finish() {
  if (!scene_.output.video) return;
  VideoRequest r;
  r.frames = dir_;
  r.firstFrame = int(std::max<long>(0, firstWritten_));
  r.frameCount = written_;
  r.fps = scene_.output.fps;
  r.file = dir_.parent_path() / (safeFileStem(scene_.name) + ".mp4");
  r.cancelled = cancelled;
  video_ = encodeVideo(r);
  videoDone_ = true;
  videoFile_ = r.file;
}

template <int D>
void ImageSink<D>::report(nlohmann::json* j) const {
  (*j)["frames_written"] = written_;
  addBytes(j, "frames", bytes_);
  if (videoDone_ && video_.written) addBytes(j, "video", fileBytes(videoFile_));
  if (!scene_.output.autoRange)
    (*j)["frames_range"] = {{"range", {scene_.output.range[0], scene_.output.range[1]}},
                            {"cells_beyond", clipped_},
                            {"fraction_beyond", cells_ > 0 ? double(clipped_) / double(cells_) : 0.0}};
  if (videoDone_)
    (*j)["video"] = {{"file", videoFile_.string()},
                     {"written", video_.written},
                     {"warning", video_.warning},
                     {"ffmpeg_log", video_.log.string()}};
}

template <int D>
std::vector<std::string> ImageSink<D>::whereToLook() const {
  std::vector<std::string> lines;
  if (videoDone_ && video_.written)
    lines.push_back(fmt::format("animation: {} (play it with `ffplay -loop 0 {}` or any video player)",
                                videoFile_.string(), videoFile_.string()));
  if (const std::filesystem::path newest = endFile(dir_, "." + scene_.output.format, true); !newest.empty())
    lines.push_back(fmt::format("newest frame: {} (of {} in {}/)", newest.string(), written_, dir_.string()));
  return lines;
}

template <int D>
nlohmann::json ImageSink<D>::state() const {
  return {{"written", written_},
          {"first_written", firstWritten_},
          {"bytes", bytes_},
          {"clipped", clipped_},
          {"cells", cells_}};
}

template <int D>
void ImageSink<D>::restore(const nlohmann::json& s) {
  written_ = stateCount<int>(s, "written");
  firstWritten_ = stateCount<long>(s, "first_written", -1);
  bytes_ = stateCount<uintmax_t>(s, "bytes");
  clipped_ = stateCount<uintmax_t>(s, "clipped");
  cells_ = stateCount<uintmax_t>(s, "cells");
}

template <int D>
FieldDumpSink<D>::FieldDumpSink(const std::filesystem::path& out) : dir_(out / kFieldFiles.folder) {
  createOutputFolder(dir_);
}

template <int D>
void FieldDumpSink<D>::write(const FrameInfo& at, const Simulation<D>& sim) {
  FieldDump d;
  d.names = sim.dumpFieldNames();
  for (const std::string& n : d.names) {
    const Grid<float, D> g = sim.field(n).front();
    if (d.resolution.empty())
      for (int a = 0; a < D; ++a) d.resolution.push_back(g.dim(a));
    d.channels.push_back(g.values());
  }
  d.time = sim.time();
  d.step = at.step;
  std::string err;
  const std::filesystem::path file = dir_ / fmt::format("{:06d}.exr", at.frame);
  if (!writeFieldDump(file.string(), d, &err)) throw std::runtime_error("writing " + file.string() + ": " + err);
  ++written_;
  bytes_ += fileBytes(file);
}

template <int D>
void FieldDumpSink<D>::report(nlohmann::json* j) const {
  (*j)["fields_written"] = written_;
  addBytes(j, "fields", bytes_);
}

template <int D>
nlohmann::json FieldDumpSink<D>::state() const {
  return {{"written", written_}, {"bytes", bytes_}};
}

template <int D>
void FieldDumpSink<D>::restore(const nlohmann::json& s) {
  written_ = stateCount<int>(s, "written");
  bytes_ = stateCount<uintmax_t>(s, "bytes");
}

template <int D>
NormalMapSink<D>::NormalMapSink(const std::filesystem::path& out, const Scene& scene)
    : normals_(out / kNormalMapFiles.folder), heights_(out / kHeightFiles.folder), scene_(scene) {
  createOutputFolder(normals_);
  createOutputFolder(heights_);
}

template <int D>
void NormalMapSink<D>::write(const FrameInfo& at, const Simulation<D>& sim) {
  if constexpr (D == 2) {
    const OutputSettings& o = scene_.output;
    const Grid<float, 2> height = sim.field(fields::kHeight).front();
    const bool periodic = scene_.rd.enabled ? scene_.rd.settings.boundary == RDBoundary::Periodic
                                            : scene_.fluid.boundaries.sides[0].kind == BoundaryKind::Periodic;
    const std::vector<uint8_t> rgb = normalMapRgb(height, {o.normalStrength, periodic});
    std::string err;
    const std::filesystem::path png = normals_ / fmt::format("{:06d}.png", at.frame);
    if (!writeRgb8(png.string(), height.dim(0), height.dim(1), rgb, &err))
      throw std::runtime_error("writing " + png.string() + ": " + err);
    FieldDump d;
    d.resolution = {height.dim(0), height.dim(1)};
    d.names = {fields::kHeight};
    d.channels = {height.values()};
    d.time = sim.time();
    d.step = at.step;
    const std::filesystem::path exr = heights_ / fmt::format("{:06d}.exr", at.frame);
    if (!writeFieldDump(exr.string(), d, &err)) throw std::runtime_error("writing " + exr.string() + ": " + err);
    ++written_;
    bytes_ += fileBytes(png) + fileBytes(exr);
  }
}

template <int D>
void NormalMapSink<D>::report(nlohmann::json* j) const {
  (*j)["normal_maps_written"] = written_;
  addBytes(j, "normal_maps", bytes_);
}

template <int D>
nlohmann::json NormalMapSink<D>::state() const {
  return {{"written", written_}, {"bytes", bytes_}};
}

template <int D>
void NormalMapSink<D>::restore(const nlohmann::json& s) {
  written_ = stateCount<int>(s, "written");
  bytes_ = stateCount<uintmax_t>(s, "bytes");
}

template <int D>
std::vector<std::unique_ptr<OutputSink<D>>> makeOutputSinks(const std::filesystem::path& out, const Scene& scene,
                                                            const std::function<bool()>& cancelled) {
  std::vector<std::unique_ptr<OutputSink<D>>> sinks;
  if (scene.output.images) {
    auto images = std::make_unique<ImageSink<D>>(out, scene);
    images->cancelled = cancelled;
    sinks.push_back(std::move(images));
  }
  if (scene.output.fields) sinks.push_back(std::make_unique<FieldDumpSink<D>>(out));
  if (scene.output.vdb) sinks.push_back(std::make_unique<VdbSink<D>>(out, scene));
  if (scene.output.normalMap) sinks.push_back(std::make_unique<NormalMapSink<D>>(out, scene));
  return sinks;
}

template class ImageSink<2>;
template class ImageSink<3>;
template class FieldDumpSink<2>;
template class FieldDumpSink<3>;
template class NormalMapSink<2>;
template class NormalMapSink<3>;
template std::vector<std::unique_ptr<OutputSink<2>>> makeOutputSinks<2>(const std::filesystem::path&, const Scene&,
                                                                         const std::function<bool()>&);
template std::vector<std::unique_ptr<OutputSink<3>>> makeOutputSinks<3>(const std::filesystem::path&, const Scene&,
                                                                         const std::function<bool()>&);

}  // namespace morphoflow
