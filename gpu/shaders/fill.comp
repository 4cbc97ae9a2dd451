// A moving solid's fill (fluid/extrapolation.h's FillPlan) on one field of
// REAL elements at `off`: MODE_COVER the covered elements take coveredValue;
// MODE_FILL the elements of one layer take the mean of their listed
// neighbours (kernels/extrapolation.inc), summed in double in the plan's order.
layout(std430, binding = 0) buffer Field { REAL field[]; };
layout(std430, binding = 1) readonly buffer Plan { uint plan[]; };
uniform int n, first, off, stride;  // MODE_COVER: first in uints; MODE_FILL: in elements
uniform double coveredValue;
#define EX_FN double
#define EX_REAL double
#include "extrapolation.inc"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_COVER)
  field[off + int(plan[first + i])] = REAL(coveredValue);
#else
  const int e = (first + i) * stride;
  const int count = int(plan[e + 1]);
  double sum = 0.0lf;
  for (int k = 0; k < count; ++k) sum += double(field[off + int(plan[e + 2 + k])]);
  field[off + int(plan[e])] = REAL(exNeighbourMean(sum, count));
#endif
}
