// Savitzky-Golay derivative kernels on a 5 x 5 neighbourhood (seed 000 sec.
// 5.1, eq. 30-35): a polynomial of total degree n, sum a_ij x^i y^j with
// i + j <= n and i, j <= 4 (five samples per axis fix no higher power), is
// fitted by least squares to the 25 samples around a cell,
// a = X^+ u (eq. 34), and d^(i+j) u / dx^i dy^j at the centre is i! j! a_ij.
// X^+ does not depend on the data, so each derivative is a fixed 5 x 5
// convolution kernel.
#pragma once

#include <array>

namespace morphoflow {

// weights[dy + 2][dx + 2]: the derivative at the centre is the sum of
// weights times u(x + dx, y + dy), in cells (divide by h^(i+j) for a grid of spacing h).
using Kernel5 = std::array<std::array<double, 5>, 5>;

// The kernel of d^(i+j)/dx^i dy^j for a fit of total degree `degree`
// (i, j <= 4, i + j <= degree <= 8). Throws std::invalid_argument otherwise.
Kernel5 savitzkyGolayDerivative(int i, int j, int degree);

}  // namespace morphoflow
