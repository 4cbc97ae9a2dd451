// Wider x86 kernels chosen at run time. The build targets x86-64-v2 (four
// float lanes, SSE); a few compute-bound kernels also have an eight-lane
// AVX2 variant, compiled for that target alone (a function attribute, not a
// flag on a whole translation unit, so no inline function elsewhere is ever
// built for AVX2) and used when the CPU has it. A wide kernel does each
// lane's arithmetic in the scalar loop's order and without FMA, so both
// variants give bitwise the same fields: the choice is one of speed only.
// The 5 x 5 kernel of the fused explicit step (its 25 weights stay in
// AVX-512's 32 registers) and the fluid's advection rows also have a
// sixteen-lane AVX-512 variant, under the same rule. MORPHOFLOW_SIMD=4 in the environment keeps the four-lane
// kernels, MORPHOFLOW_SIMD=8 the eight-lane ones.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MORPHOFLOW_AVX2_KERNELS 1
#else
#define MORPHOFLOW_AVX2_KERNELS 0
#endif

// A helper of a wide kernel, always inlined into it, so that inside a
// target("avx2") kernel it compiles for AVX2 too.
#define MF_INLINE __attribute__((always_inline)) inline

namespace morphoflow {

// Eight float lanes (GCC vector extensions, as core/simd4.h's four): one
// AVX2 register inside a target("avx2") kernel.
typedef float vf8 __attribute__((vector_size(32)));
typedef int vi8 __attribute__((vector_size(32)));
// Sixteen: one AVX-512 register inside a target("avx512f") kernel.
typedef float vf16 __attribute__((vector_size(64)));
typedef int vi16 __attribute__((vector_size(64)));

// True when the CPU (and this build) can run the AVX2 kernels.
bool cpuHasAvx2();
// Whether the kernels use their AVX2 variants now: cpuHasAvx2(), unless
// MORPHOFLOW_SIMD=4 or setUseAvx2(false).
bool useAvx2();
// Tests compare the two variants; asking for AVX2 on a CPU without it keeps
// the four-lane kernels.
void setUseAvx2(bool on);
// The same for the AVX-512 variants (AVX-512 F and VL), used only while
// useAvx2() is too.
bool cpuHasAvx512();
bool useAvx512();
void setUseAvx512(bool on);

}  // namespace morphoflow
