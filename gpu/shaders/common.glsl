// Prepended to the flat kernels (gpu/gpu_kernels.h): one invocation per
// sample, 256 a work group, the groups laid out over x and y so a grid of
// more than 2^24 samples fits the dispatch limits.
layout(local_size_x = 256) in;

int flatIndex() {
  return int((gl_WorkGroupID.x + gl_NumWorkGroups.x * gl_WorkGroupID.y) * 256u + gl_LocalInvocationID.x);
}
// x fastest, as core/grid.h
ivec3 coordsOf(int i, ivec3 d) { return ivec3(i % d.x, (i / d.x) % d.y, i / (d.x * d.y)); }
int indexOf(ivec3 c, ivec3 d) { return c.x + d.x * (c.y + d.y * c.z); }
// c + s e_a, wrapped into [0, n) (steps of one cell)
ivec3 stepWrapped(ivec3 c, int a, int s, ivec3 n) {
  c[a] += s;
  if (c[a] < 0) c[a] += n[a];
  if (c[a] >= n[a]) c[a] -= n[a];
  return c;
}
