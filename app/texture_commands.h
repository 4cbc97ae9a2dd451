// `morphoflow analyze` (seed 003's variogram and REG of an image or a field
// dump) and `morphoflow texton` (random-walk texton textures, seed 003 eq. 6).
#pragma once

#include <string>
#include <vector>

#include "rd/texton_walk.h"

namespace morphoflow {

struct AnalyzeOptions {
  std::string file;
  std::string channel;   // empty: the first
  int maxLag = 0;        // 0: a quarter of the smaller side
  bool periodic = false;
  int slice = -1;        // 3D dumps: z slice (-1 = middle)
  std::string csv;       // also write the variogram table here
  bool legibility = false;  // a rendered element's legibility instead (render/legibility.h)
};
int analyzeCommand(const AnalyzeOptions& options);

struct TextonOptions {
  TextonWalkSettings walk;
  std::string start = "pulse";  // pulse | regular | uniform
  std::string out;              // .png (grey) or .exr (float channel "t")
  bool analyze = false;         // also print REG of the result
};
int textonCommand(TextonOptions options);

// `morphoflow plot propagator SCENE --out FILE.png`: the Gram-Charlier
// propagator (seed 000 eq. 23-24) of the scene's [rd.generalized] tensors as a
// polar plot of p(r) on |r| = radius at time tau (seed 000 fig. 1: 1 and 0.1).
struct PlotOptions {
  std::string what;     // "propagator"
  std::string scene;
  std::vector<std::string> overrides;
  std::string out;
  double tau = 0.1, radius = 1.0;
  int size = 512;
};
int plotCommand(const PlotOptions& options);

}  // namespace morphoflow
