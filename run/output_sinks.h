// The outputs a run writes at every frame, each a sink the run driver feeds
// with a Simulation's named fields: image frames (DIR/frames/NNNNNN.png|exr,
// and the mp4 made of them at the end), field dumps (DIR/fields/NNNNNN.exr),
// volumes (DIR/vdb/<name>.NNNNNN.vdb|nvdb, run/vdb_sink.h).
// Every file is written to a temporary name and renamed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <stdexcept>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/simulation.h"
#include "render/field_image.h"
#include "render/video.h"
#include "scenes/scene.h"

namespace morphoflow {

// Which frame a sink is fed, and where the run is.
struct FrameInfo {
  long frame = 0, step = 0;
  double dt = 0.0;  // the last step's (frame 0: the first's)
};

template <int D>
class OutputSink {
 public:
  virtual ~OutputSink() = default;
  virtual void write(const FrameInfo& at, const Simulation<D>& sim) = 0;
  // After the last frame (the video is made here).
  virtual void finish() {}
  // Its entries in run.json (its counts, and its bytes under "bytes_written").
  virtual void report(nlohmann::json* run) const = 0;
  // What it must remember across a checkpoint (counts, the first frame).
  virtual nlohmann::json state() const = 0;
  virtual void restore(const nlohmann::json& state) = 0;
  // Lines said at the end of a run: what it wrote and how to look at it.
  virtual std::vector<std::string> whereToLook() const { return {}; }
};

// The scene's field through its palette (or two species in red and green).
template <int D>
class ImageSink : public OutputSink<D> {
 public:
  ImageSink(const std::filesystem::path& out, const Scene& scene);
  void write(const FrameInfo& at, const Simulation<D>& sim) override;
  void finish() override;
  void report(nlohmann::json* run) const override;
  nlohmann::json state() const override;
  void restore(const nlohmann::json& state) override;
  std::vector<std::string> whereToLook() const override;
  // Polled while the video is encoded: true stops it.
  std::function<bool()> cancelled;

 private:
  std::filesystem::path dir_;
  const Scene& scene_;
  int written_ = 0;
  long firstWritten_ = -1;
  uintmax_t bytes_ = 0;
  uintmax_t clipped_ = 0,
            cells_ = 0;  // a fixed output.range: the shown cells beyond it (drawn at its ends), of all shown
  bool videoDone_ = false;
  VideoResult video_;
  std::filesystem::path videoFile_;
};

// Every field of the simulation's dump list as full-precision float channels.
template <int D>
class FieldDumpSink : public OutputSink<D> {
 public:
  explicit FieldDumpSink(const std::filesystem::path& out);
  void write(const FrameInfo& at, const Simulation<D>& sim) override;
  void report(nlohmann::json* run) const override;
  nlohmann::json state() const override;
  void restore(const nlohmann::json& state) override;

 private:
  std::filesystem::path dir_;
  int written_ = 0;
  uintmax_t bytes_ = 0;
};

// The shown field as a height field in [0, 1] (the frames' value range): its
// tangent-space normal map (DIR/normals/NNNNNN.png) and the height itself as a
// float EXR (DIR/height/NNNNNN.exr), seamless where the layer is periodic.
template <int D>
class NormalMapSink : public OutputSink<D> {
 public:
  NormalMapSink(const std::filesystem::path& out, const Scene& scene);
  void write(const FrameInfo& at, const Simulation<D>& sim) override;
  void report(nlohmann::json* run) const override;
  nlohmann::json state() const override;
  void restore(const nlohmann::json& state) override;

 private:
  std::filesystem::path normals_, heights_;
  const Scene& scene_;
  int written_ = 0;
  uintmax_t bytes_ = 0;
};

// The sinks the scene's [output] asks for; `cancelled` stops a video encode.
template <int D>
std::vector<std::unique_ptr<OutputSink<D>>> makeOutputSinks(const std::filesystem::path& out, const Scene& scene,
                                                            const std::function<bool()>& cancelled);

// The first or the last file in `dir` whose name ends in `extension` (by name: frames are zero-padded), or "".
std::filesystem::path endFile(const std::filesystem::path& dir, const std::string& extension, bool last);
// The bytes of a file just written (0 when it is not there).
uintmax_t fileBytes(const std::filesystem::path& file);
// Adds `bytes` to run["bytes_written"][kind].
void addBytes(nlohmann::json* run, const std::string& kind, uintmax_t bytes);
// A count kept in a sink's checkpoint state: an integer at least `lowest`
// that fits T, else std::invalid_argument naming the key.
template <class T>
T stateCount(const nlohmann::json& state, const char* key, long long lowest = 0) {
  const nlohmann::json& v = state.at(key);
  if (!v.is_number_integer()) throw std::invalid_argument(std::string("'") + key + "' is not an integer");
  const auto outOfRange = [key] { return std::invalid_argument(std::string("'") + key + "' is out of range"); };
  if (v.is_number_unsigned()) {
    const unsigned long long u = v.get<unsigned long long>();
    if (u > static_cast<unsigned long long>(std::numeric_limits<T>::max())) throw outOfRange();
    return T(u);
  }
  const long long n = v.get<long long>();
  if (n < lowest ||
      (n > 0 && static_cast<unsigned long long>(n) > static_cast<unsigned long long>(std::numeric_limits<T>::max())))
    throw outOfRange();
  return T(n);
}

}  // namespace morphoflow
