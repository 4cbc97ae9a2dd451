// Frames of a run: which steps write one (output.every, --frames A:B), and
// writing a scalar field through the scene's colormap to DIR/frames/NNNNNN.png.
#pragma once

#include <filesystem>

#include "app/run_options.h"
#include "core/grid.h"
#include "scenes/scene.h"

namespace morphoflow {

class FrameWriter {
 public:
  FrameWriter(const std::filesystem::path& out, const OutputSettings& output, const RunOptions& options);
  // The frame number step writes, or -1 if it writes none.
  long frameAt(long step) const;
  // Writes `field` as frame `frame`; `symmetric` centres an automatic range on 0.
  template <int D>
  void write(long frame, const Grid<float, D>& field, bool symmetric);
  int written() const { return written_; }

 private:
  std::filesystem::path dir_;
  const OutputSettings& output_;
  const RunOptions& options_;
  int written_ = 0;
};

}  // namespace morphoflow
