// `morphoflow sweep --vary`: the values one scene key takes across a sweep.
//   key=start:stop:count   count evenly spaced numbers, both ends included
//   key=[a,b,c]            the listed TOML values
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

struct Vary {
  std::string key;
  std::vector<std::string> values;  // TOML text, as --set takes it
  std::vector<std::string> labels;  // the same for folder names and labels ("gray-scott", 0.035)
};

// Throws UserError naming --vary and what to write instead.
Vary parseVary(const std::string& text);

// The Cartesian product, the first key varying slowest; each variant is one
// value index per key.
std::vector<std::vector<size_t>> cartesianProduct(const std::vector<Vary>& varies);

}  // namespace morphoflow
