// The reaction models of the seed papers, each a small struct:
//   N species, P parameters, info() (names, defaults, equations), and
//   static rates(x, p, r) / jacobian(x, p, J) for one cell (J row-major,
//   J[s * N + t] = dR_s / dx_t).
// The two-species models take x as T: a double, or a vector of doubles for
// several cells at once (rd/newton_batch.h), each lane with the double's
// arithmetic. So a constant is written c - T() (exactly c in every lane, -0
// included) and a max as a select.
// Diffusion defaults assume the units the source uses (cell size 1 unless
// the scene's domain says otherwise); every default is overridable.
#pragma once

#include <algorithm>
#include <cmath>

#include "rd/reaction_model.h"

namespace morphoflow::models {

// Seed 002 (Lawlor), continuous form of Turing's equations:
//   a' = s (alpha - a b),  b' = s (a b - b - beta);  b is clamped at 0.
struct Turing {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"turing", "Turing spots (Lawlor 2003, seed 002; Turk 1991)",
            "da/dt = s (alpha - a b) + d_a lap a\ndb/dt = s (a b - b - beta) + d_b lap b   (b clamped at 0)",
            {"a", "b"},
            {{"s", 1.0 / 128, "reaction rate"}, {"alpha", 16.0, "growth of a"}, {"beta", 12.0, "decay of b"}},
            {0.25, 0.0625}, {4.0, 4.0}, 0.0, 16.0, true, {1}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    r[0] = p[0] * (p[1] - x[0] * x[1]);
    r[1] = p[0] * (x[0] * x[1] - x[1] - p[2]);
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    J[0] = -p[0] * x[1], J[1] = -p[0] * x[0];
    J[2] = p[0] * x[1], J[3] = p[0] * (x[0] - 1.0);
  }
};

// Seed 004 (Sanderson et al.) eq. 3-4, also Kim & Lin appendix A:
//   a' = s (a b - a - alpha),  b' = s (beta - a b);  a is clamped at 0.
struct TuringSanderson {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"turing-sanderson", "Turing spots, Sanderson et al. form (seed 004 eq. 3-4; seed 001 appendix A)",
            "da/dt = s (a b - a - alpha) + d_a lap a   (a clamped at 0)\ndb/dt = s (beta - a b) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0 / 128, "reaction rate"}, {"alpha", 12.0, "decay of a"}, {"beta", 16.0, "growth of b"}},
            {1.0 / 16, 1.0 / 4}, {4.0, 4.0}, 0.0, 16.0, true, {0}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    r[0] = p[0] * (x[0] * x[1] - x[0] - p[1]);
    r[1] = p[0] * (p[2] - x[0] * x[1]);
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    J[0] = p[0] * (x[1] - 1.0), J[1] = p[0] * x[0];
    J[2] = -p[0] * x[1], J[3] = -p[0] * x[0];
  }
};

// Pearson 1993 (Gray & Scott), seed 001 eq. 7-8:
//   u' = -u v^2 + F (1 - u),  v' = u v^2 - (F + k) v.
struct GrayScott {
  static constexpr int N = 2, P = 2;
  static ModelInfo info() {
    return {"gray-scott", "Gray-Scott (Pearson 1993; seed 001 eq. 7-8)",
            "du/dt = -u v^2 + F (1 - u) + d_u lap u\ndv/dt = u v^2 - (F + k) v + d_v lap v",
            {"u", "v"},
            {{"F", 0.04, "feed rate"}, {"k", 0.06, "kill rate"}},
            {2e-5, 1e-5}, {1.0, 0.0}, 0.0, 1.0, false, {}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    const T uvv = x[0] * x[1] * x[1];
    r[0] = -uvv + p[0] * (1.0 - x[0]);
    r[1] = uvv - (p[0] + p[1]) * x[1];
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    J[0] = -x[1] * x[1] - p[0], J[1] = -2.0 * x[0] * x[1];
    J[2] = x[1] * x[1], J[3] = 2.0 * x[0] * x[1] - (p[0] + p[1]);
  }
};

// Seed 004 eq. 5-6: a' = s (a^2 b - (F + k) a),  b' = s (-a^2 b + F (1 - b)).
struct GrayScottSanderson {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"gray-scott-sanderson", "Gray-Scott, Sanderson et al. form (seed 004 eq. 5-6)",
            "da/dt = s (a^2 b - (F + k) a) + d_a lap a\ndb/dt = s (-a^2 b + F (1 - b)) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0, "reaction rate"}, {"F", 0.04, "feed rate"}, {"k", 0.06, "kill rate"}},
            {1e-5, 2e-5}, {0.0, 1.0}, 0.0, 1.0, false, {}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    const T aab = x[0] * x[0] * x[1];
    r[0] = p[0] * (aab - (p[1] + p[2]) * x[0]);
    r[1] = p[0] * (-aab + p[1] * (1.0 - x[1]));
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    J[0] = p[0] * (2.0 * x[0] * x[1] - (p[1] + p[2])), J[1] = p[0] * x[0] * x[0];
    J[2] = -2.0 * p[0] * x[0] * x[1], J[3] = -p[0] * (x[0] * x[0] + p[1]);
  }
};

// Seed 001 appendix A: A' = A - A^3 - B,  B' = eps (A - a1 B - a0).
struct FitzHughNagumo {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"fitzhugh-nagumo", "FitzHugh-Nagumo (seed 001 appendix A)",
            "dA/dt = A - A^3 - B + d_A lap A\ndB/dt = eps (A - a1 B - a0) + d_B lap B",
            {"A", "B"},
            {{"eps", 0.02, "time-scale ratio"}, {"a0", -0.8, "offset"}, {"a1", 1.0, "recovery slope"}},
            {1.0, 0.0}, {-0.9283, -0.1283}, -2.0, 2.0, false, {}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    r[0] = x[0] - x[0] * x[0] * x[0] - x[1];
    r[1] = p[0] * (x[0] - p[2] * x[1] - p[1]);
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    J[0] = 1.0 - 3.0 * x[0] * x[0], J[1] = -1.0 - T();
    J[2] = p[0] - T(), J[3] = -p[0] * p[2] - T();
  }
};

// Seed 001 appendix A (Barkley 1991): A' = (1/eps) A (1 - A) (A - (B + b) / a),
// B' = A - B; the turbulent variant (Bar & Eiswirth) has B' = A^3 - B.
template <bool Turbulent>
struct BarkleyT {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {Turbulent ? "barkley-turbulent" : "barkley",
            Turbulent ? "Barkley, turbulent variant (seed 001 appendix A)" : "Barkley (seed 001 appendix A)",
            Turbulent ? "dA/dt = (1/eps) A (1 - A) (A - (B + b)/a) + d_A lap A\ndB/dt = A^3 - B + d_B lap B"
                      : "dA/dt = (1/eps) A (1 - A) (A - (B + b)/a) + d_A lap A\ndB/dt = A - B + d_B lap B",
            {"A", "B"},
            {{"a", 0.75, "excitation threshold slope"}, {"b", 0.02, "threshold offset"}, {"eps", 0.02, "stiffness"}},
            {1.0, 0.0}, {0.0, 0.0}, 0.0, 1.0, false, {}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    const T th = (x[1] + p[1]) / p[0];
    r[0] = x[0] * (1.0 - x[0]) * (x[0] - th) / p[2];
    if constexpr (Turbulent)
      r[1] = x[0] * x[0] * x[0] - x[1];
    else
      r[1] = x[0] - x[1];
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    const T A = x[0], th = (x[1] + p[1]) / p[0], g = A - A * A;
    J[0] = ((1.0 - 2.0 * A) * (A - th) + g) / p[2];
    J[1] = -g / (p[0] * p[2]);
    if constexpr (Turbulent)
      J[2] = 3.0 * A * A;
    else
      J[2] = 1.0 - T();
    J[3] = -1.0 - T();
  }
};
using Barkley = BarkleyT<false>;
using BarkleyTurbulent = BarkleyT<true>;

// Seed 001 appendix A (Meinhardt spots):
//   A' = s (p1 A + 0.01 alpha A^2 / B + p3),  B' = s (p2 B + 0.01 alpha A^2).
struct MeinhardtSpots {
  static constexpr int N = 2, P = 5;
  static constexpr double kFloor = 1e-9;  // B > 0 (it divides)
  static ModelInfo info() {
    return {"meinhardt", "Meinhardt spots (seed 001 appendix A)",
            "dA/dt = s (p1 A + 0.01 alpha A^2 / B + p3) + d_A lap A\ndB/dt = s (p2 B + 0.01 alpha A^2) + d_B lap B",
            {"A", "B"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 1.0, "autocatalysis"}, {"p1", -0.04, "decay of A"},
             {"p2", -0.08, "decay of B"}, {"p3", 0.001, "basic production of A"}},
            {0.1, 4.0}, {2.025, 0.5126}, 0.0, 8.0, true, {0}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    const T B = x[1] < kFloor ? kFloor - T() : x[1], aa = 0.01 * p[1] * x[0] * x[0];
    r[0] = p[0] * (p[2] * x[0] + aa / B + p[4]);
    r[1] = p[0] * (p[3] * x[1] + aa);
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    const T B = x[1] < kFloor ? kFloor - T() : x[1], aa = 0.01 * p[1] * x[0] * x[0];
    J[0] = p[0] * (p[2] + 0.02 * p[1] * x[0] / B);
    J[1] = x[1] > kFloor ? -p[0] * aa / (B * B) : T();
    J[2] = p[0] * 0.02 * p[1] * x[0], J[3] = p[0] * p[3] - T();
  }
};

// Seed 004 eq. 7-8 (Prigogine & Lefever):
//   a' = s (alpha - (1 + beta) a + a^2 b),  b' = s (beta a - a^2 b).
struct Brusselator {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"brusselator", "Brusselator (seed 004 eq. 7-8)",
            "da/dt = s (alpha - (1 + beta) a + a^2 b) + d_a lap a\ndb/dt = s (beta a - a^2 b) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 3.0, "feed"}, {"beta", 9.0, "conversion"}},
            {49.5, 117.6}, {3.0, 3.0}, 0.0, 8.0, false, {}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    const T aab = x[0] * x[0] * x[1];
    r[0] = p[0] * (p[1] - (1.0 + p[2]) * x[0] + aab);
    r[1] = p[0] * (p[2] * x[0] - aab);
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    J[0] = p[0] * (2.0 * x[0] * x[1] - (1.0 + p[2])), J[1] = p[0] * x[0] * x[0];
    J[2] = p[0] * (p[2] - 2.0 * x[0] * x[1]), J[3] = -p[0] * x[0] * x[0];
  }
};

// Seed 004 eq. 9-10: a' = s (gamma + a^2 / b - alpha a),  b' = s (a^2 - beta b).
struct GiererMeinhardt {
  static constexpr int N = 2, P = 4;
  static constexpr double kFloor = 1e-9;
  static ModelInfo info() {
    return {"gierer-meinhardt", "Gierer-Meinhardt (seed 004 eq. 9-10)",
            "da/dt = s (gamma + a^2 / b - alpha a) + d_a lap a\ndb/dt = s (a^2 - beta b) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 0.5, "decay of a"}, {"beta", 1.0, "decay of b"},
             {"gamma", 0.1, "basic production of a"}},
            {1.0, 40.0}, {2.2, 4.84}, 0.0, 10.0, true, {0}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    const T b = x[1] < kFloor ? kFloor - T() : x[1];
    r[0] = p[0] * (p[3] + x[0] * x[0] / b - p[1] * x[0]);
    r[1] = p[0] * (x[0] * x[0] - p[2] * x[1]);
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    const T b = x[1] < kFloor ? kFloor - T() : x[1];
    J[0] = p[0] * (2.0 * x[0] / b - p[1]);
    J[1] = x[1] > kFloor ? -p[0] * x[0] * x[0] / (b * b) : T();
    J[2] = 2.0 * p[0] * x[0], J[3] = -p[0] * p[2] - T();
  }
};

// Seed 004 eq. 27-28 (Field & Noyes):
//   a' = (1/eps) (a - a^2 - f b (a - q) / (a + q)),  b' = a - b.
struct Oregonator {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"oregonator", "Oregonator (seed 004 eq. 27-28)",
            "da/dt = (1/eps) (a - a^2 - f b (a - q)/(a + q)) + d_a lap a\n"
            "db/dt = a - b + d_b lap b",
            {"a", "b"},
            {{"eps", 0.05, "time-scale ratio"}, {"f", 1.4, "stoichiometry"}, {"q", 0.002, "scaling"}},
            {1.0, 0.6}, {0.0, 0.0}, 0.0, 1.0, false, {}};
  }
  template <class T>
  static void rates(const T* x, const double* p, T* r) {
    const T a = x[0] < 0.0 ? T() : x[0];
    r[0] = (x[0] - x[0] * x[0] - p[1] * x[1] * (a - p[2]) / (a + p[2])) / p[0];
    r[1] = x[0] - x[1];
  }
  template <class T>
  static void jacobian(const T* x, const double* p, T* J) {
    const T a = x[0] < 0.0 ? T() : x[0], aq = a + p[2];
    J[0] = (1.0 - 2.0 * x[0] - (x[0] > 0.0 ? p[1] * x[1] * 2.0 * p[2] / (aq * aq) : T())) / p[0];
    J[1] = -p[1] * (a - p[2]) / aq / p[0];
    J[2] = 1.0 - T(), J[3] = -1.0 - T();
  }
};

// Seed 003 eq. 3 (Meinhardt's lateral activation of locally exclusive states):
//   g1' = c s2 g1^2 / r - alpha g1 + rho0,   g2' = c s1 g2^2 / r - alpha g2 + rho0,
//   r'  = c s2 g1^2 + c s1 g2^2 - beta r,
//   s1' = gamma (g1 - s1) + rho1,            s2' = gamma (g2 - s2) + rho1.
// (The seed's text prints "- c s1 g2^2" in r'; Meinhardt's common repressor
// is produced by both feedback loops, so both terms are added here.)
struct MeinhardtLateral {
  static constexpr int N = 5, P = 6;
  static constexpr double kFloor = 1e-9;
  static ModelInfo info() {
    return {"meinhardt-lateral", "Meinhardt lateral activation, five species (seed 003 eq. 3)",
            "dg1/dt = c s2 g1^2 / r - alpha g1 + rho0 + d_g lap g1\n"
            "dg2/dt = c s1 g2^2 / r - alpha g2 + rho0 + d_g lap g2\n"
            "dr/dt  = c s2 g1^2 + c s1 g2^2 - beta r + d_r lap r\n"
            "ds1/dt = gamma (g1 - s1) + rho1 + d_s lap s1\n"
            "ds2/dt = gamma (g2 - s2) + rho1 + d_s lap s2",
            {"g1", "g2", "r", "s1", "s2"},
            {{"c", 1.0, "autocatalysis"}, {"alpha", 0.1, "decay of g"}, {"beta", 0.1, "decay of r"},
             {"gamma", 0.1, "relaxation of s to g"}, {"rho0", 0.001, "basic production of g"},
             {"rho1", 0.0, "basic production of s"}},
            {0.01, 0.01, 0.0, 0.4, 0.4}, {0.51, 0.51, 2.65, 0.51, 0.51}, 0.0, 4.0, true, {0, 1, 3, 4}};
  }
  static void rates(const double* x, const double* p, double* r) {
    double rr = std::max(x[2], kFloor), a = p[0] * x[4] * x[0] * x[0], b = p[0] * x[3] * x[1] * x[1];
    r[0] = a / rr - p[1] * x[0] + p[4];
    r[1] = b / rr - p[1] * x[1] + p[4];
    r[2] = a + b - p[2] * x[2];
    r[3] = p[3] * (x[0] - x[3]) + p[5];
    r[4] = p[3] * (x[1] - x[4]) + p[5];
  }
  static void jacobian(const double* x, const double* p, double* J) {
    double rr = std::max(x[2], kFloor), c = p[0];
    double a = c * x[4] * x[0] * x[0], b = c * x[3] * x[1] * x[1];
    double dr = x[2] > kFloor ? 1.0 / (rr * rr) : 0.0;
    std::fill(J, J + 25, 0.0);
    J[0] = 2.0 * c * x[4] * x[0] / rr - p[1], J[2] = -a * dr, J[4] = c * x[0] * x[0] / rr;
    J[6] = 2.0 * c * x[3] * x[1] / rr - p[1], J[7] = -b * dr, J[8] = c * x[1] * x[1] / rr;
    J[10] = 2.0 * c * x[4] * x[0], J[11] = 2.0 * c * x[3] * x[1], J[12] = -p[2], J[13] = c * x[1] * x[1],
    J[14] = c * x[0] * x[0];
    J[15] = p[3], J[18] = -p[3];
    J[21] = p[3], J[24] = -p[3];
  }
};

// Seed 004 eq. 20-21: two Brusselator layers, linearly coupled,
//   a_i' = F(a_i, b_i) + mu (a_j - a_i),  b_i' = G(a_i, b_i) + nu (b_j - b_i).
struct CoupledBrusselator {
  static constexpr int N = 4, P = 5;
  static ModelInfo info() {
    return {"brusselator-coupled", "Two linearly coupled Brusselator layers (seed 004 eq. 20-21)",
            "da1/dt = F(a1, b1) + mu (a2 - a1) + d_a1 lap a1\ndb1/dt = G(a1, b1) + nu (b2 - b1) + d_b1 lap b1\n"
            "da2/dt = F(a2, b2) + mu (a1 - a2) + d_a2 lap a2\ndb2/dt = G(a2, b2) + nu (b1 - b2) + d_b2 lap b2\n"
            "F, G: the Brusselator (s, alpha, beta)",
            {"a1", "b1", "a2", "b2"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 3.0, "feed"}, {"beta", 9.0, "conversion"},
             {"mu", 0.1, "coupling of a"}, {"nu", 0.1, "coupling of b"}},
            {16.7, 36.4, 49.5, 117.6}, {3.0, 3.0, 3.0, 3.0}, 0.0, 8.0, false, {}};
  }
  static void rates(const double* x, const double* p, double* r) {
    Brusselator::rates(x, p, r);
    Brusselator::rates(x + 2, p, r + 2);
    r[0] += p[3] * (x[2] - x[0]), r[2] += p[3] * (x[0] - x[2]);
    r[1] += p[4] * (x[3] - x[1]), r[3] += p[4] * (x[1] - x[3]);
  }
  static void jacobian(const double* x, const double* p, double* J) {
    double j1[4], j2[4];
    Brusselator::jacobian(x, p, j1);
    Brusselator::jacobian(x + 2, p, j2);
    std::fill(J, J + 16, 0.0);
    J[0] = j1[0] - p[3], J[1] = j1[1], J[2] = p[3];
    J[4] = j1[2], J[5] = j1[3] - p[4], J[7] = p[4];
    J[8] = p[3], J[10] = j2[0] - p[3], J[11] = j2[1];
    J[13] = p[4], J[14] = j2[2], J[15] = j2[3] - p[4];
  }
};

// Seed 004 eq. 22-28: two Oregonator layers coupled through a middle layer c,
//   a' = F(a,b) - (a - c)/delta,  b' = G(a,b),
//   c' = (a - c)/delta + (d - c)/delta_bar,
//   d' = F'(d,e) - (d - c)/delta_bar,  e' = G(d,e).
// (The seed prints 1/delta in the d equation; delta_bar keeps the exchange
// between c and d symmetric, and the two agree at the default delta_bar = delta.)
struct OregonatorThreeLayer {
  static constexpr int N = 5, P = 8;
  static ModelInfo info() {
    return {"oregonator-3layer", "Three-layer Oregonator (seed 004 eq. 22-28)",
            "da/dt = F(a, b) - (a - c)/delta + d_a lap a\ndb/dt = a - b + d_b lap b\n"
            "dc/dt = (a - c)/delta + (d - c)/delta_bar + d_c lap c\n"
            "dd/dt = F'(d, e) - (d - c)/delta_bar + d_d lap d\nde/dt = d - e + d_e lap e\n"
            "F = (1/eps)(a - a^2 - f b (a - q)/(a + q)); F' uses eps2, f2, q2",
            {"a", "b", "c", "d", "e"},
            {{"eps", 0.05, "top-layer time-scale ratio"}, {"f", 1.4, "top-layer stoichiometry"},
             {"q", 0.002, "top-layer scaling"}, {"eps2", 0.05, "bottom-layer time-scale ratio"},
             {"f2", 1.1, "bottom-layer stoichiometry"}, {"q2", 0.002, "bottom-layer scaling"},
             {"delta", 2.0, "top/middle exchange time"}, {"delta_bar", 2.0, "middle/bottom exchange time"}},
            {1.0, 0.6, 1.0, 1.0, 0.6}, {0.0, 0.0, 0.0, 0.0, 0.0}, 0.0, 1.0, false, {}};
  }
  static void rates(const double* x, const double* p, double* r) {
    double top[2], bot[2], pt[3] = {p[0], p[1], p[2]}, pb[3] = {p[3], p[4], p[5]};
    double xb[2] = {x[3], x[4]};
    Oregonator::rates(x, pt, top);
    Oregonator::rates(xb, pb, bot);
    double ac = (x[0] - x[2]) / p[6], dc = (x[3] - x[2]) / p[7];
    r[0] = top[0] - ac, r[1] = top[1];
    r[2] = ac + dc;
    r[3] = bot[0] - dc, r[4] = bot[1];
  }
  static void jacobian(const double* x, const double* p, double* J) {
    double jt[4], jb[4], pt[3] = {p[0], p[1], p[2]}, pb[3] = {p[3], p[4], p[5]};
    double xb[2] = {x[3], x[4]};
    Oregonator::jacobian(x, pt, jt);
    Oregonator::jacobian(xb, pb, jb);
    std::fill(J, J + 25, 0.0);
    double id = 1.0 / p[6], ib = 1.0 / p[7];
    J[0] = jt[0] - id, J[1] = jt[1], J[2] = id;
    J[5] = jt[2], J[6] = jt[3];
    J[10] = id, J[12] = -id - ib, J[13] = ib;
    J[17] = ib, J[18] = jb[0] - ib, J[19] = jb[1];
    J[23] = jb[2], J[24] = jb[3];
  }
};

}  // namespace morphoflow::models
