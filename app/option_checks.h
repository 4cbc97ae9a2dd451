// Checks of the command line's numbers where they are parsed: a whole token,
// finite, and inside the range the option can use (CLI11's own Range lets
// "nan" through, and an "inf" or a 1e300 reaches the code it would break).
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/number_text.h"

namespace morphoflow {

// A finite number in [lo, hi].
inline CLI::Validator finiteIn(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const auto v = parseNumber(text);
        if (!v) return "expected a finite number, got '" + text + "'";
        if (*v < lo || *v > hi) return fmt::format("{} is outside [{:g}, {:g}]", text, lo, hi);
        return "";
      },
      fmt::format("in [{:g}, {:g}]", lo, hi));
}

}  // namespace morphoflow
