// Frames of a run: which steps write one (output.every, --frames A:B);
// writing a scalar field through the scene's palette (or two species in red
// and green) to DIR/frames/NNNNNN.png|exr, and float dumps of named fields to
// DIR/fields/NNNNNN.exr when output.fields is set; and the frames as an mp4
// when output.video is set.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "app/run_options.h"
#include "core/grid.h"
#include "render/video.h"
#include "scenes/scene.h"

namespace morphoflow {

class FrameWriter {
 public:
  FrameWriter(const std::filesystem::path& out, const OutputSettings& output, const RunOptions& options);
  // The frame number step writes, or -1 if it writes none.
  long frameAt(long step) const;
  // Writes `field` as image frame `frame` (when output.images); `symmetric`
  // centres an automatic range on 0; `green`, if given, is shown in green
  // with `field` in red (the two-species palette).
  template <int D>
  void write(long frame, const Grid<float, D>& field, bool symmetric, const Grid<float, D>* green = nullptr);
  // Writes the named fields as one float EXR (when output.fields).
  template <int D>
  void writeFields(long frame, const std::vector<std::string>& names, const std::vector<Grid<float, D>>& fields,
                   double time, long step);
  // After the last frame: encodes the image frames into OUT/<name>.mp4 when
  // output.video is set (render/video.h); a failure is a warning on stderr
  // and in run.json, never an error: the frames stay.
  void finishVideo(const std::string& name);
  // run.json's "video" entry (null when output.video is off).
  const VideoResult* video() const { return videoDone_ ? &video_ : nullptr; }
  const std::filesystem::path& videoFile() const { return videoFile_; }
  int written() const { return written_; }
  int fieldsWritten() const { return fieldsWritten_; }

 private:
  std::filesystem::path dir_, fieldsDir_;
  const OutputSettings& output_;
  const RunOptions& options_;
  int written_ = 0, fieldsWritten_ = 0;
  long firstWritten_ = -1;
  bool videoDone_ = false;
  VideoResult video_;
  std::filesystem::path videoFile_;
};

}  // namespace morphoflow
