// The reaction models of the seed papers, each a small struct:
//   N species, P parameters, info() (names, defaults, equations), and
//   static rates(x, p, r) / jacobian(x, p, J) for one cell (J row-major,
//   J[s * N + t] = dR_s / dx_t).
// The rates and Jacobians are written once, in kernels/models/*.inc, in the
// subset of C++ and GLSL that both compile (kernels/README.md): this header
// includes them into the structs, and the GPU backend embeds the same files
// into its shaders (gpu/gpu_models.h). Here T is a double, or a vector of
// doubles or floats for several cells at once (rd/newton_batch.h,
// rd/fused_explicit.cpp), each lane with the scalar's arithmetic: so a
// constant is TV(c) = c - T() (exactly c in every lane, -0 included) and a
// max is a select. A model built from another's layers (the coupled
// Brusselator, the three-layer Oregonator) derives from it for its kernels.
// Diffusion defaults assume the units the source uses (cell size 1 unless
// the scene's domain says otherwise); every default is overridable.
#pragma once

#include <tuple>
#include <type_traits>

#include "rd/reaction_model.h"

// The C++ side of the kernels' dialect (kernels/README.md).
#define RATES template <class T> static void rates(const T* x, const double* p, T* r)
#define JACOBIAN template <class T> static void jacobian(const T* x, const double* p, T* J)
#define KERNEL template <class T> static void
#define OUT(type, name) type& name
#define PT double
#define PRECISE
#define LIT(v) v
#define TV(v) ((v) - T())
#define TURBULENT Turbulent

namespace morphoflow::models {

// The rates and Jacobian: kernels/models/turing.inc
struct Turing {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"turing", "Turing spots (Lawlor 2003, seed 002; Turk 1991)",
            "da/dt = s (alpha - a b) + d_a lap a\ndb/dt = s (a b - b - beta) + d_b lap b   (b clamped at 0)",
            {"a", "b"},
            {{"s", 1.0 / 128, "reaction rate"}, {"alpha", 16.0, "growth of a"}, {"beta", 12.0, "decay of b"}},
            {0.25, 0.0625}, {4.0, 4.0}, 0.0, 16.0, {1}};
  }
  static constexpr const char* kKernel = "turing.inc";
#include "kernels/models/turing.inc"
};

// The rates and Jacobian: kernels/models/turing_sanderson.inc
struct TuringSanderson {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"turing-sanderson", "Turing spots, Sanderson et al. form (seed 004 eq. 3-4; seed 001 appendix A)",
            "da/dt = s (a b - a - alpha) + d_a lap a   (a clamped at 0)\ndb/dt = s (beta - a b) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0 / 128, "reaction rate"}, {"alpha", 12.0, "decay of a"}, {"beta", 16.0, "growth of b"}},
            {1.0 / 16, 1.0 / 4}, {4.0, 4.0}, 0.0, 16.0, {0}};
  }
  static constexpr const char* kKernel = "turing_sanderson.inc";
#include "kernels/models/turing_sanderson.inc"
};

// The rates and Jacobian: kernels/models/gray_scott.inc
struct GrayScott {
  static constexpr int N = 2, P = 2;
  static ModelInfo info() {
    return {"gray-scott", "Gray-Scott (Pearson 1993; seed 001 eq. 7-8)",
            "du/dt = -u v^2 + F (1 - u) + d_u lap u\ndv/dt = u v^2 - (F + k) v + d_v lap v",
            {"u", "v"},
            {{"F", 0.04, "feed rate"}, {"k", 0.06, "kill rate"}},
            {2e-5, 1e-5}, {1.0, 0.0}, 0.0, 1.0, {}};
  }
  static constexpr const char* kKernel = "gray_scott.inc";
#include "kernels/models/gray_scott.inc"
};

// The rates and Jacobian: kernels/models/gray_scott_sanderson.inc
struct GrayScottSanderson {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"gray-scott-sanderson", "Gray-Scott, Sanderson et al. form (seed 004 eq. 5-6)",
            "da/dt = s (a^2 b - (F + k) a) + d_a lap a\ndb/dt = s (-a^2 b + F (1 - b)) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0, "reaction rate"}, {"F", 0.04, "feed rate"}, {"k", 0.06, "kill rate"}},
            {1e-5, 2e-5}, {0.0, 1.0}, 0.0, 1.0, {}};
  }
  static constexpr const char* kKernel = "gray_scott_sanderson.inc";
#include "kernels/models/gray_scott_sanderson.inc"
};

// The rates and Jacobian: kernels/models/fitzhugh_nagumo.inc
struct FitzHughNagumo {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"fitzhugh-nagumo", "FitzHugh-Nagumo (seed 001 appendix A)",
            "dA/dt = A - A^3 - B + d_A lap A\ndB/dt = eps (A - a1 B - a0) + d_B lap B",
            {"A", "B"},
            {{"eps", 0.02, "time-scale ratio"}, {"a0", -0.8, "offset"}, {"a1", 1.0, "recovery slope"}},
            {1.0, 0.0}, {-0.9283, -0.1283}, -2.0, 2.0, {}};
  }
  static constexpr const char* kKernel = "fitzhugh_nagumo.inc";
#include "kernels/models/fitzhugh_nagumo.inc"
};

// The rates and Jacobian: kernels/models/barkley.inc
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
            {1.0, 0.0}, {0.0, 0.0}, 0.0, 1.0, {}};
  }
  static constexpr const char* kKernel = "barkley.inc";
  static constexpr const char* kKernelDefines = Turbulent ? "#define TURBULENT true\n" : "#define TURBULENT false\n";
#include "kernels/models/barkley.inc"
};
using Barkley = BarkleyT<false>;
using BarkleyTurbulent = BarkleyT<true>;

// The rates and Jacobian: kernels/models/meinhardt.inc
struct MeinhardtSpots {
  static constexpr int N = 2, P = 5;
  static ModelInfo info() {
    return {"meinhardt", "Meinhardt spots (seed 001 appendix A)",
            "dA/dt = s (p1 A + 0.01 alpha A^2 / B + p3) + d_A lap A\ndB/dt = s (p2 B + 0.01 alpha A^2) + d_B lap B",
            {"A", "B"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 1.0, "autocatalysis"}, {"p1", -0.04, "decay of A"},
             {"p2", -0.08, "decay of B"}, {"p3", 0.001, "basic production of A"}},
            {0.1, 4.0}, {2.025, 0.5126}, 0.0, 8.0, {0}};
  }
  static constexpr const char* kKernel = "meinhardt.inc";
#include "kernels/models/meinhardt.inc"
};

// The rates and Jacobian: kernels/models/brusselator.inc
struct Brusselator {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"brusselator", "Brusselator (seed 004 eq. 7-8)",
            "da/dt = s (alpha - (1 + beta) a + a^2 b) + d_a lap a\ndb/dt = s (beta a - a^2 b) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 3.0, "feed"}, {"beta", 9.0, "conversion"}},
            {49.5, 117.6}, {3.0, 3.0}, 0.0, 8.0, {}};
  }
  static constexpr const char* kKernel = "brusselator.inc";
#include "kernels/models/brusselator.inc"
};

// The rates and Jacobian: kernels/models/gierer_meinhardt.inc
struct GiererMeinhardt {
  static constexpr int N = 2, P = 4;
  static ModelInfo info() {
    return {"gierer-meinhardt", "Gierer-Meinhardt (seed 004 eq. 9-10)",
            "da/dt = s (gamma + a^2 / b - alpha a) + d_a lap a\ndb/dt = s (a^2 - beta b) + d_b lap b",
            {"a", "b"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 0.5, "decay of a"}, {"beta", 1.0, "decay of b"},
             {"gamma", 0.1, "basic production of a"}},
            {1.0, 40.0}, {2.2, 4.84}, 0.0, 10.0, {0}};
  }
  static constexpr const char* kKernel = "gierer_meinhardt.inc";
#include "kernels/models/gierer_meinhardt.inc"
};

// The rates and Jacobian: kernels/models/oregonator.inc
struct Oregonator {
  static constexpr int N = 2, P = 3;
  static ModelInfo info() {
    return {"oregonator", "Oregonator (seed 004 eq. 27-28)",
            "da/dt = (1/eps) (a - a^2 - f b (a - q)/(a + q)) + d_a lap a\n"
            "db/dt = a - b + d_b lap b",
            {"a", "b"},
            {{"eps", 0.05, "time-scale ratio"}, {"f", 1.4, "stoichiometry"}, {"q", 0.002, "scaling"}},
            {1.0, 0.6}, {0.0, 0.0}, 0.0, 1.0, {}};
  }
  static constexpr const char* kKernel = "oregonator.inc";
#include "kernels/models/oregonator.inc"
};

// The rates and Jacobian: kernels/models/meinhardt_lateral.inc
struct MeinhardtLateral {
  static constexpr int N = 5, P = 6;
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
            {0.01, 0.01, 0.0, 0.4, 0.4}, {0.51, 0.51, 2.65, 0.51, 0.51}, 0.0, 4.0, {0, 1, 3, 4}};
  }
  static constexpr const char* kKernel = "meinhardt_lateral.inc";
#include "kernels/models/meinhardt_lateral.inc"
};

// The rates and Jacobian: kernels/models/brusselator_coupled.inc
struct CoupledBrusselator : Brusselator {
  static constexpr int N = 4, P = 5;
  static ModelInfo info() {
    return {"brusselator-coupled", "Two linearly coupled Brusselator layers (seed 004 eq. 20-21)",
            "da1/dt = F(a1, b1) + mu (a2 - a1) + d_a1 lap a1\ndb1/dt = G(a1, b1) + nu (b2 - b1) + d_b1 lap b1\n"
            "da2/dt = F(a2, b2) + mu (a1 - a2) + d_a2 lap a2\ndb2/dt = G(a2, b2) + nu (b1 - b2) + d_b2 lap b2\n"
            "F, G: the Brusselator (s, alpha, beta)",
            {"a1", "b1", "a2", "b2"},
            {{"s", 1.0, "reaction rate"}, {"alpha", 3.0, "feed"}, {"beta", 9.0, "conversion"},
             {"mu", 0.1, "coupling of a"}, {"nu", 0.1, "coupling of b"}},
            {16.7, 36.4, 49.5, 117.6}, {3.0, 3.0, 3.0, 3.0}, 0.0, 8.0, {}};
  }
  static constexpr const char* kKernel = "brusselator_coupled.inc";
  static constexpr const char* kKernelBase = "brusselator.inc";  // its kernels, included first
#include "kernels/models/brusselator_coupled.inc"
};

// The rates and Jacobian: kernels/models/oregonator_3layer.inc
struct OregonatorThreeLayer : Oregonator {
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
            {1.0, 0.6, 1.0, 1.0, 0.6}, {0.0, 0.0, 0.0, 0.0, 0.0}, 0.0, 1.0, {}};
  }
  static constexpr const char* kKernel = "oregonator_3layer.inc";
  static constexpr const char* kKernelBase = "oregonator.inc";  // its kernels, included first
#include "kernels/models/oregonator_3layer.inc"
};

// Every model, in the order `morphoflow list` shows them. The registry
// (rd/model_registry.cpp) and the fused step (rd/fused_explicit.cpp) walk
// this one list.
using All = std::tuple<Turing, TuringSanderson, GrayScott, GrayScottSanderson, FitzHughNagumo, Barkley,
                       BarkleyTurbulent, MeinhardtSpots, Brusselator, GiererMeinhardt, Oregonator, MeinhardtLateral,
                       CoupledBrusselator, OregonatorThreeLayer>;

// Calls f(std::type_identity<M>{}) for each model M of All, in order.
template <class F>
void forEach(F&& f) {
  [&]<class... M>(std::tuple<M...>*) { (f(std::type_identity<M>{}), ...); }(static_cast<All*>(nullptr));
}

}  // namespace morphoflow::models

#undef RATES
#undef JACOBIAN
#undef KERNEL
#undef OUT
#undef PT
#undef PRECISE
#undef LIT
#undef TV
#undef TURBULENT
