// `morphoflow bench studio`: what watching costs the simulation, and how
// soon an edit shows (docs/performance.md, "The studio").
#pragma once

#include <string>

namespace morphoflow {

// Times the shipped coupled cavity at 256^2 chemicals and its 3D twin at
// 64^3: steps/s alone against steps/s in the studio with one client taking
// every frame, in interleaved rounds of `seconds` each; then the time from a
// deposit posted to the first frame computed after it. Prints a table;
// writes JSON to `json` when given.
void runStudioBench(const std::string& sceneDir, double seconds, const std::string& json);

}  // namespace morphoflow
