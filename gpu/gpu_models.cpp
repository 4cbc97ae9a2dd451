#include "gpu/gpu_models.h"

#include <map>

namespace morphoflow {

namespace {

struct Model {
  const char* rates;     // r[0], r[1] from x[0], x[1] and p[k]
  const char* jacobian;  // J[0..3]
};

// rd/models.h with the same operations in the same order; T is the
// precision, C(v) a constant in it (v is not exact in float).
const std::map<std::string, Model>& models() {
  static const std::map<std::string, Model> m = {
      {"turing",
       {"r[0] = p[0] * (p[1] - x[0] * x[1]); r[1] = p[0] * (x[0] * x[1] - x[1] - p[2]);",
        "J[0] = -p[0] * x[1]; J[1] = -p[0] * x[0]; J[2] = p[0] * x[1]; J[3] = p[0] * (x[0] - 1.0);"}},
      {"turing-sanderson",
       {"r[0] = p[0] * (x[0] * x[1] - x[0] - p[1]); r[1] = p[0] * (p[2] - x[0] * x[1]);",
        "J[0] = p[0] * (x[1] - 1.0); J[1] = p[0] * x[0]; J[2] = -p[0] * x[1]; J[3] = -p[0] * x[0];"}},
      {"gray-scott",
       {"T uvv = x[0] * x[1] * x[1]; r[0] = -uvv + p[0] * (1.0 - x[0]); r[1] = uvv - (p[0] + p[1]) * x[1];",
        "J[0] = -x[1] * x[1] - p[0]; J[1] = -2.0 * x[0] * x[1]; J[2] = x[1] * x[1]; J[3] = 2.0 * x[0] * x[1] - (p[0] + p[1]);"}},
      {"gray-scott-sanderson",
       {"T aab = x[0] * x[0] * x[1]; r[0] = p[0] * (aab - (p[1] + p[2]) * x[0]); r[1] = p[0] * (-aab + p[1] * (1.0 - x[1]));",
        "J[0] = p[0] * (2.0 * x[0] * x[1] - (p[1] + p[2])); J[1] = p[0] * x[0] * x[0]; J[2] = -2.0 * p[0] * x[0] * x[1]; "
        "J[3] = -p[0] * (x[0] * x[0] + p[1]);"}},
      {"fitzhugh-nagumo",
       {"r[0] = x[0] - x[0] * x[0] * x[0] - x[1]; r[1] = p[0] * (x[0] - p[2] * x[1] - p[1]);",
        "J[0] = 1.0 - 3.0 * x[0] * x[0]; J[1] = T(-1.0); J[2] = p[0]; J[3] = -p[0] * p[2];"}},
      {"barkley",
       {"T th = (x[1] + p[1]) / p[0]; r[0] = x[0] * (1.0 - x[0]) * (x[0] - th) / p[2]; r[1] = x[0] - x[1];",
        "T A = x[0], th = (x[1] + p[1]) / p[0], g = A - A * A; J[0] = ((1.0 - 2.0 * A) * (A - th) + g) / p[2]; "
        "J[1] = -g / (p[0] * p[2]); J[2] = T(1.0); J[3] = T(-1.0);"}},
      {"barkley-turbulent",
       {"T th = (x[1] + p[1]) / p[0]; r[0] = x[0] * (1.0 - x[0]) * (x[0] - th) / p[2]; r[1] = x[0] * x[0] * x[0] - x[1];",
        "T A = x[0], th = (x[1] + p[1]) / p[0], g = A - A * A; J[0] = ((1.0 - 2.0 * A) * (A - th) + g) / p[2]; "
        "J[1] = -g / (p[0] * p[2]); J[2] = 3.0 * A * A; J[3] = T(-1.0);"}},
      {"meinhardt",
       {"T B = x[1] < C(1e-9) ? C(1e-9) : x[1], aa = C(0.01) * p[1] * x[0] * x[0]; "
        "r[0] = p[0] * (p[2] * x[0] + aa / B + p[4]); r[1] = p[0] * (p[3] * x[1] + aa);",
        "T B = x[1] < C(1e-9) ? C(1e-9) : x[1], aa = C(0.01) * p[1] * x[0] * x[0]; "
        "J[0] = p[0] * (p[2] + C(0.02) * p[1] * x[0] / B); J[1] = x[1] > C(1e-9) ? -p[0] * aa / (B * B) : T(0.0); "
        "J[2] = p[0] * C(0.02) * p[1] * x[0]; J[3] = p[0] * p[3];"}},
      {"brusselator",
       {"T aab = x[0] * x[0] * x[1]; r[0] = p[0] * (p[1] - (1.0 + p[2]) * x[0] + aab); r[1] = p[0] * (p[2] * x[0] - aab);",
        "J[0] = p[0] * (2.0 * x[0] * x[1] - (1.0 + p[2])); J[1] = p[0] * x[0] * x[0]; J[2] = p[0] * (p[2] - 2.0 * x[0] * x[1]); "
        "J[3] = -p[0] * x[0] * x[0];"}},
      {"gierer-meinhardt",
       {"T b = x[1] < C(1e-9) ? C(1e-9) : x[1]; r[0] = p[0] * (p[3] + x[0] * x[0] / b - p[1] * x[0]); "
        "r[1] = p[0] * (x[0] * x[0] - p[2] * x[1]);",
        "T b = x[1] < C(1e-9) ? C(1e-9) : x[1]; J[0] = p[0] * (2.0 * x[0] / b - p[1]); "
        "J[1] = x[1] > C(1e-9) ? -p[0] * x[0] * x[0] / (b * b) : T(0.0); J[2] = 2.0 * p[0] * x[0]; J[3] = -p[0] * p[2];"}},
      {"oregonator",
       {"T a = x[0] < 0.0 ? T(0.0) : x[0]; r[0] = (x[0] - x[0] * x[0] - p[1] * x[1] * (a - p[2]) / (a + p[2])) / p[0]; "
        "r[1] = x[0] - x[1];",
        "T a = x[0] < 0.0 ? T(0.0) : x[0], aq = a + p[2]; "
        "J[0] = (1.0 - 2.0 * x[0] - (x[0] > 0.0 ? p[1] * x[1] * 2.0 * p[2] / (aq * aq) : T(0.0))) / p[0]; "
        "J[1] = -p[1] * (a - p[2]) / aq / p[0]; J[2] = T(1.0); J[3] = T(-1.0);"}},
  };
  return m;
}

}  // namespace

std::string gpuReaction(const std::string& name, bool doublePrecision) {
  const auto it = models().find(name);
  if (it == models().end()) return "";
  return std::string(doublePrecision ? "#define T double\n#define C(v) v##lf\n" : "#define T float\n#define C(v) v\n") +
         "#define RATES(x, r) { " + it->second.rates + " }\n#define JACOBIAN(x, J) { " + it->second.jacobian + " }\n";
}

}  // namespace morphoflow
