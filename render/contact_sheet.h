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

// Writes the sheet as a PNG (atomically). Throws std::runtime_error when a
// frame cannot be read or the sheet written.
void writeContactSheet(const std::string& path, const ContactSheet& sheet);

}  // namespace morphoflow
