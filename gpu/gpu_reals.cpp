#include "gpu/gpu_reals.h"

namespace morphoflow {

std::string realDefines(GpuPrecision p, GpuPrecision solution) {
  return std::string(solution == GpuPrecision::Float ? "#define XREAL float\n" : "#define XREAL double\n") +
         (p == GpuPrecision::Float
              ? "#define REAL float\n#define REAL2 vec2\n#define REAL3 vec3\n"
                "#define REAL_HUGE 3.0e38\n#define REAL_TINY 1.0e-37\n"
              : "#define REAL double\n#define REAL_IS_DOUBLE\n#define REAL2 dvec2\n#define REAL3 dvec3\n"
                "#define REAL_HUGE 1e300lf\n#define REAL_TINY 1e-300lf\n");
}

GpuBuffer realBuffer(size_t n, GpuPrecision p) {
  GpuBuffer b(n * realBytes(p));
  b.zero();
  return b;
}

GpuBuffer realBuffer(const std::vector<double>& values, GpuPrecision p) {
  GpuBuffer b(values.size() * realBytes(p));
  uploadReals(&b, values, p);
  return b;
}

void uploadReals(GpuBuffer* b, const std::vector<double>& values, GpuPrecision p, size_t firstElement) {
  if (p == GpuPrecision::Double) return b->upload(values, firstElement * sizeof(double));
  b->upload(std::vector<float>(values.begin(), values.end()), firstElement * sizeof(float));
}

std::vector<double> readReals(const GpuBuffer& b, size_t n, GpuPrecision p, size_t firstElement) {
  if (p == GpuPrecision::Double) return b.read<double>(n, firstElement * sizeof(double));
  const std::vector<float> v = b.read<float>(n, firstElement * sizeof(float));
  return std::vector<double>(v.begin(), v.end());
}

}  // namespace morphoflow
