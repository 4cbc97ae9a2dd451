// `morphoflow batch`, `morphoflow sweep` and `morphoflow gather`: many runs,
// each in its own child process, with a summary (stdout and DIR/batch.json).
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

struct BatchOptions {
  std::vector<std::string> scenes;  // batch: the scene files; sweep: the one scene
  std::vector<std::string> varies;  // sweep: key=start:stop:count or key=[a,b,c]
  std::vector<std::string> sets;    // --set key=value, for every run
  std::string shard;                // "I/N": every N-th run from the I-th (0-based)
  int jobs = 1;                     // runs at once; the machine's threads are divided between them
  bool keepGoing = false;           // run the valid scenes when some are invalid
  bool resume = false;              // skip completed runs, resume interrupted ones
  bool quiet = false;
  std::string out = "out";
  std::string executable;           // the morphoflow executable the runs use (empty: this process's)
};

// Each returns the exit status: 0 when every run completed, 2 when any was a
// user error, 1 otherwise, 128 + the signal when SIGINT or SIGTERM stopped
// the batch. Throws UserError on bad options.
int runBatch(const BatchOptions& options);
int runSweep(const BatchOptions& options);
// Merges the shards' summaries in `dir` into DIR/batch.json (and, for a
// sweep, sweep.csv and contact_sheet.png); prints the table.
int gatherBatch(const std::string& dir);

}  // namespace morphoflow
