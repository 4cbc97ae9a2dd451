// dst = src, four floats an invocation: the kernel the device's copy
// bandwidth is measured by (gpu/gpu_copy_bandwidth.h).
layout(std430, binding = 0) readonly buffer Src { vec4 src[]; };
layout(std430, binding = 1) writeonly buffer Dst { vec4 dst[]; };
uniform int n;  // vec4s

void main() {
  const int i = flatIndex();
  if (i < n) dst[i] = src[i];
}
