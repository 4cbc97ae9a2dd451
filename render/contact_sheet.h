// A sweep's contact sheet: the last frame of every variant in a labelled
// grid, columns by the first varied key, rows by the others (the picture of
// Pearson's Gray-Scott classes).
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

struct ContactSheet {
  std::string title;                  // e.g. "columns: rd.params.F   rows: rd.params.k"
  std::vector<std::string> columns;   // column labels
  std::vector<std::string> rows;      // row labels
  std::vector<std::string> images;    // rows x columns, row-major; "" where a variant has no frame
  int cellWidth = 160;                // pixels per cell; each frame is scaled to it
};

// Writes the sheet as a PNG (atomically). A frame that cannot be read is a
// grey cell, as a missing one is; each such frame ("PATH: why") is returned.
// Throws OutputError when the sheet cannot be written.
std::vector<std::string> writeContactSheet(const std::string& path, const ContactSheet& sheet);

}  // namespace morphoflow
