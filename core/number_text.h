// Numbers on the command line are whole tokens: "12" is 12, "12x", " 12",
// "1e400" and "" are not numbers at all (std::stoi would read "12x" as 12).
#pragma once

#include <optional>
#include <string>

namespace morphoflow {

// A decimal integer, optionally signed, that fits a long.
std::optional<long> parseWhole(const std::string& text);
// A finite decimal number (integer, fraction or exponent form).
std::optional<double> parseNumber(const std::string& text);

}  // namespace morphoflow
