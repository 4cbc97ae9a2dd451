#include "gpu/gpu_models.h"

#include <map>

#include <fmt/format.h>

namespace morphoflow {

namespace {

struct Model {
  const char* rates;     // r[s] from x[t] and p[k]
  const char* jacobian;  // J[s * N + t] (the entries not set are 0)
  int species = 2;
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
      // The multi-species models, their sums in the CPU's order (rd/models.h).
      {"meinhardt-lateral",
       {"T rr = max(x[2], C(1e-9)), a = p[0] * x[4] * x[0] * x[0], b = p[0] * x[3] * x[1] * x[1]; "
        "r[0] = a / rr - p[1] * x[0] + p[4]; r[1] = b / rr - p[1] * x[1] + p[4]; r[2] = a + b - p[2] * x[2]; "
        "r[3] = p[3] * (x[0] - x[3]) + p[5]; r[4] = p[3] * (x[1] - x[4]) + p[5];",
        "T rr = max(x[2], C(1e-9)), c = p[0]; T a = c * x[4] * x[0] * x[0], b = c * x[3] * x[1] * x[1]; "
        "T dr = x[2] > C(1e-9) ? 1.0 / (rr * rr) : T(0.0); "
        "J[0] = 2.0 * c * x[4] * x[0] / rr - p[1]; J[2] = -a * dr; J[4] = c * x[0] * x[0] / rr; "
        "J[6] = 2.0 * c * x[3] * x[1] / rr - p[1]; J[7] = -b * dr; J[8] = c * x[1] * x[1] / rr; "
        "J[10] = 2.0 * c * x[4] * x[0]; J[11] = 2.0 * c * x[3] * x[1]; J[12] = -p[2]; J[13] = c * x[1] * x[1]; "
        "J[14] = c * x[0] * x[0]; J[15] = p[3]; J[18] = -p[3]; J[21] = p[3]; J[24] = -p[3];",
        5}},
      {"brusselator-coupled",
       {"T aab = x[0] * x[0] * x[1], ccd = x[2] * x[2] * x[3]; "
        "r[0] = p[0] * (p[1] - (1.0 + p[2]) * x[0] + aab); r[1] = p[0] * (p[2] * x[0] - aab); "
        "r[2] = p[0] * (p[1] - (1.0 + p[2]) * x[2] + ccd); r[3] = p[0] * (p[2] * x[2] - ccd); "
        "r[0] += p[3] * (x[2] - x[0]); r[2] += p[3] * (x[0] - x[2]); r[1] += p[4] * (x[3] - x[1]); r[3] += p[4] * (x[1] - x[3]);",
        "T j0 = p[0] * (2.0 * x[0] * x[1] - (1.0 + p[2])), j1 = p[0] * x[0] * x[0], j2 = p[0] * (p[2] - 2.0 * x[0] * x[1]), "
        "j3 = -p[0] * x[0] * x[0]; "
        "T k0 = p[0] * (2.0 * x[2] * x[3] - (1.0 + p[2])), k1 = p[0] * x[2] * x[2], k2 = p[0] * (p[2] - 2.0 * x[2] * x[3]), "
        "k3 = -p[0] * x[2] * x[2]; "
        "J[0] = j0 - p[3]; J[1] = j1; J[2] = p[3]; J[4] = j2; J[5] = j3 - p[4]; J[7] = p[4]; "
        "J[8] = p[3]; J[10] = k0 - p[3]; J[11] = k1; J[13] = p[4]; J[14] = k2; J[15] = k3 - p[4];",
        4}},
      {"oregonator-3layer",
       {"T a = x[0] < 0.0 ? T(0.0) : x[0], d = x[3] < 0.0 ? T(0.0) : x[3]; "
        "T top = (x[0] - x[0] * x[0] - p[1] * x[1] * (a - p[2]) / (a + p[2])) / p[0]; "
        "T bot = (x[3] - x[3] * x[3] - p[4] * x[4] * (d - p[5]) / (d + p[5])) / p[3]; "
        "T ac = (x[0] - x[2]) / p[6], dc = (x[3] - x[2]) / p[7]; "
        "r[0] = top - ac; r[1] = x[0] - x[1]; r[2] = ac + dc; r[3] = bot - dc; r[4] = x[3] - x[4];",
        "T a = x[0] < 0.0 ? T(0.0) : x[0], aq = a + p[2], d = x[3] < 0.0 ? T(0.0) : x[3], dq = d + p[5]; "
        "T t0 = (1.0 - 2.0 * x[0] - (x[0] > 0.0 ? p[1] * x[1] * 2.0 * p[2] / (aq * aq) : T(0.0))) / p[0]; "
        "T t1 = -p[1] * (a - p[2]) / aq / p[0]; "
        "T b0 = (1.0 - 2.0 * x[3] - (x[3] > 0.0 ? p[4] * x[4] * 2.0 * p[5] / (dq * dq) : T(0.0))) / p[3]; "
        "T b1 = -p[4] * (d - p[5]) / dq / p[3]; T id = 1.0 / p[6], ib = 1.0 / p[7]; "
        "J[0] = t0 - id; J[1] = t1; J[2] = id; J[5] = T(1.0); J[6] = T(-1.0); "
        "J[10] = id; J[12] = -id - ib; J[13] = ib; J[17] = ib; J[18] = b0 - ib; J[19] = b1; J[23] = T(1.0); J[24] = T(-1.0);",
        5}},
  };
  return m;
}

}  // namespace

int gpuSpecies(const std::string& name) {
  const auto it = models().find(name);
  return it == models().end() ? 0 : it->second.species;
}

std::string gpuReaction(const std::string& name, bool doublePrecision) {
  const auto it = models().find(name);
  if (it == models().end() || (!doublePrecision && it->second.species != 2)) return "";
  return fmt::format("#define NSPECIES {}\n", it->second.species) +
         std::string(doublePrecision ? "#define T double\n#define C(v) v##lf\n" : "#define T float\n#define C(v) v\n") +
         "#define RATES(x, r) { " + it->second.rates + " }\n#define JACOBIAN(x, J) { " + it->second.jacobian + " }\n";
}

}  // namespace morphoflow
