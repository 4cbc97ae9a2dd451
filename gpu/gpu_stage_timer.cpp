#include "gpu/gpu_stage_timer.h"

#include <epoxy/gl.h>

namespace morphoflow {

GpuStageTimer::GpuStageTimer(int stages) : stages_(stages), counts_(size_t(stages)) {
  for (auto& q : queries_) {
    q.resize(size_t(stages + 1));
    glGenQueries(GLsizei(q.size()), q.data());
  }
}

GpuStageTimer::~GpuStageTimer() {
  for (auto& q : queries_) glDeleteQueries(GLsizei(q.size()), q.data());
}

void GpuStageTimer::mark(int boundary) {
  glQueryCounter(queries_[size_t(current_)][size_t(boundary)], GL_TIMESTAMP);
  const GpuCounts now = gpuCounts();
  if (boundary > 0) counts_[size_t(boundary - 1)] += now - atMark_;
  atMark_ = now;
}

std::vector<double> GpuStageTimer::endStep() {
  std::vector<double> seconds(size_t(stages_), 0.0);
  const std::vector<unsigned>& last = queries_[size_t(1 - current_)];
  if (previous_) {
    std::vector<GLuint64> t(last.size());
    for (size_t k = 0; k < last.size(); ++k) glGetQueryObjectui64v(last[k], GL_QUERY_RESULT, &t[k]);
    for (int k = 0; k < stages_; ++k) seconds[size_t(k)] = 1e-9 * double(t[size_t(k) + 1] - t[size_t(k)]);
  }
  previous_ = true;
  current_ = 1 - current_;
  ++steps_;
  return seconds;
}

nlohmann::json GpuStageTimer::countsPerStep(const char* const* names) const {
  nlohmann::json j = nlohmann::json::object();
  for (int k = 0; k < stages_; ++k) j[names[k]] = perStep(counts_[size_t(k)], steps_);
  return j;
}

}  // namespace morphoflow
