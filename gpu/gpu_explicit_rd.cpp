#include "gpu/gpu_explicit_rd.h"


#include <epoxy/gl.h>
#include <fmt/format.h>

#include "gpu/compute_program.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_counts.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_models.h"

namespace morphoflow {

namespace {
constexpr int kGroup = 8;  // 8 x 8 (x 4 in 3D) invocations a work group
}

GpuExplicitRD::GpuExplicitRD(const RDSettings& s, const std::vector<double>& diffusion,
                             const std::vector<double>& params, const std::vector<int>& clamped,
                             const std::vector<float>& u, const std::vector<float>& v) {
  GlContext::instance();
  const int D = int(s.resolution.size());
  for (int a = 0; a < D; ++a) cells_[size_t(a)] = s.resolution[size_t(a)];
  n_ = size_t(cells_[0]) * size_t(cells_[1]) * size_t(cells_[2]);
  h_ = s.size[0] / s.resolution[0];
  for (int k = 0; k < 2; ++k) dOverH2_[size_t(k)] = float(diffusion[size_t(k)] / (h_ * h_));
  for (size_t k = 0; k < params.size() && k < params_.size(); ++k) params_[k] = float(params[k]);
  periodic_ = s.boundary == RDBoundary::Periodic;
  for (int k : clamped) clamped_ |= 1u << k;
  const std::string reaction = gpuReaction(s.model, GpuPrecision::Float);
  program_ = std::make_unique<ComputeProgram>(
      "rd_explicit.comp", fmt::format("#define DIM {}\n{}\nlayout(local_size_x = {}, local_size_y = {}, "
                                      "local_size_z = {}) in;",
                                      D, reaction, kGroup, kGroup, D == 3 ? 4 : 1));
  glCreateBuffers(4, buffers_.data());
  for (unsigned b : buffers_) glNamedBufferStorage(b, GLsizeiptr(n_ * sizeof(float)), nullptr, GL_DYNAMIC_STORAGE_BIT);
  GlContext::check("allocating the species' buffers");
  upload(0, u);
  upload(1, v);
}

GpuExplicitRD::~GpuExplicitRD() { glDeleteBuffers(4, buffers_.data()); }

void GpuExplicitRD::step(double dt) {
  program_->use();
  glUniform3i(program_->uniform("cells"), cells_[0], cells_[1], cells_[2]);
  glUniform1i(program_->uniform("periodic"), periodic_ ? 1 : 0);
  glUniform1f(program_->uniform("dt"), float(dt));
  glUniform2f(program_->uniform("dOverH2"), dOverH2_[0], dOverH2_[1]);
  glUniform1fv(program_->uniform("p"), GLsizei(params_.size()), params_.data());
  glUniform1ui(program_->uniform("clamped"), clamped_);
  const int in = current_ * 2, out = 2 - current_ * 2;
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers_[size_t(in)]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers_[size_t(in + 1)]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buffers_[size_t(out)]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, buffers_[size_t(out + 1)]);
  const int gz = cells_[2] > 1 ? 4 : 1;
  glDispatchCompute(GLuint((cells_[0] + kGroup - 1) / kGroup), GLuint((cells_[1] + kGroup - 1) / kGroup),
                    GLuint((cells_[2] + gz - 1) / gz));
  countDispatch();
  countGpuTraffic(16.0 * double(n_));  // two species read and written
  // The next step reads what this one wrote, through storage buffers.
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  current_ = 1 - current_;
  GlContext::check("the explicit reaction-diffusion step");
}

void GpuExplicitRD::finish() const {
  glFinish();
  countHostWait();
}

std::vector<float> GpuExplicitRD::download(int species) const {
  std::vector<float> out(n_);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(buffers_[size_t(current_ * 2 + species)], 0, GLsizeiptr(n_ * sizeof(float)), out.data());
  countHostWait();
  GlContext::check("reading a species back");
  return out;
}

void GpuExplicitRD::upload(int species, const std::vector<float>& values) {
  glNamedBufferSubData(buffers_[size_t(current_ * 2 + species)], 0, GLsizeiptr(n_ * sizeof(float)), values.data());
  GlContext::check("writing a species");
}

}  // namespace morphoflow
