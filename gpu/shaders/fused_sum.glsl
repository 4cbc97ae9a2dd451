// A reduction's partial pass fused into the kernel that makes its terms, in
// reduce.comp's order (gpu/gpu_reduction.h), so the sums are bitwise those
// of a separate reduction: the kernel runs the reduction's groups, each
// invocation strides over the cells as MODE_PARTIAL does (FOR_REDUCTION),
// and writePartial puts the group's tree sum at partial[slot * 256 + group].
// finalSum re-sums a slot's partials as MODE_FINAL does, in every group that
// needs the scalar (the pass a separate one-group dispatch would make).
// Declare `partial` (the reduction's partials buffer) before including.
shared dvec2 fusedTree[256];

#define FOR_REDUCTION(i, n) \
  for (int i = int(gl_WorkGroupID.x) * 256 + int(gl_LocalInvocationID.x); i < (n); i += int(gl_NumWorkGroups.x) * 256)

// The group's tree sums of two terms at once (each component in
// reduce.comp's tree order; a single sum leaves y at 0).
dvec2 groupTreeSum(dvec2 s) {
  const int lid = int(gl_LocalInvocationID.x);
  fusedTree[lid] = s;
  barrier();
  for (int half_ = 128; half_ > 0; half_ >>= 1) {
    if (lid < half_) fusedTree[lid] = fusedTree[lid] + fusedTree[lid + half_];
    barrier();
  }
  const dvec2 total = fusedTree[0];
  barrier();
  return total;
}

void writePartials(dvec2 s, int slotX, int slotY) {
  const dvec2 total = groupTreeSum(s);
  if (gl_LocalInvocationID.x == 0u) {
    partial[slotX * 256 + int(gl_WorkGroupID.x)] = total.x;
    if (slotY >= 0) partial[slotY * 256 + int(gl_WorkGroupID.x)] = total.y;
  }
}

void writePartial(double s, int slot) { writePartials(dvec2(s, 0.0lf), slot, -1); }

// The sum of a slot's `groups` partials (every invocation of the group gets
// it): MODE_FINAL's tree, walked by one invocation (two barriers, not nine:
// the groups of a kernel each make this pass).
double finalSum(int slot, int groups) {
  const int lid = int(gl_LocalInvocationID.x);
  double s = 0.0lf;
  if (lid < groups) s = s + partial[slot * 256 + lid];
  fusedTree[lid].x = s;
  barrier();
  if (lid == 0) {
    for (int half_ = 128; half_ > 0; half_ >>= 1)
      for (int k = 0; k < half_; ++k) fusedTree[k].x = fusedTree[k].x + fusedTree[k + half_].x;
  }
  barrier();
  const double total = fusedTree[0].x;
  barrier();
  return total;
}
