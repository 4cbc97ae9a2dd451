// Texture synthesis by random-walk placement of textons (Manian & Vasquez,
// seed 003 sec. 3.1). Elements start on a grid (all at the centre, a regular
// lattice, or uniformly at random) and at every step each one, independently
// (seed 003 eq. 6):
//   expires                          with probability 1/L,
//   stays                            (1 - 1/L)(1 - p - q),
//   moves one step up-left/down-left  0.5 (1 - 1/L) q each,
//   moves one step up-right/down-right 0.5 (1 - 1/L) p each,
// where a step is `stepSize` cells along both axes. An element that would
// leave the field is placed on its boundary. p = q = 0.5 is the unbiased walk.
//
//   TextonWalkSettings s;  s.elements = 50;  s.steps = 100;  s.stepSize = 2;  // seed 003 fig. 8
//   std::vector<double> image = renderTextons(textonWalk(s), s);
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace morphoflow {

enum class TextonStart { Pulse, Regular, Uniform };

struct TextonWalkSettings {
  int width = 256, height = 256;  // the field, in cells
  int elements = 50;
  int steps = 100;
  int stepSize = 2;               // cells per move along each axis
  double lifetime = 0.0;          // L, mean steps to expiry; 0: elements never expire
  double p = 0.5, q = 0.5;        // move right / left, given not expired
  TextonStart start = TextonStart::Pulse;
  double radius = 3.0;            // rendered texton: an antialiased disc of this radius (cells)
  uint64_t seed = 1;
};

// Throws std::invalid_argument naming the bad setting (p + q > 1, sizes < 1, ...).
void checkTextonWalk(const TextonWalkSettings& s);

// Positions (x, y) of the elements still alive after s.steps steps.
std::vector<std::array<int, 2>> textonWalk(const TextonWalkSettings& s);

// Starting positions (step 0).
std::vector<std::array<int, 2>> textonStart(const TextonWalkSettings& s);

// One step of eq. 6 for element e at step k: the new position, or false when it expired.
bool textonStep(const TextonWalkSettings& s, uint64_t element, uint64_t step, std::array<int, 2>* position);

// A width x height image (x fastest, y up) of discs at the positions, values in [0, 1].
std::vector<double> renderTextons(const std::vector<std::array<int, 2>>& positions, const TextonWalkSettings& s);

}  // namespace morphoflow
