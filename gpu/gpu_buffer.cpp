#include "gpu/gpu_buffer.h"

#include <algorithm>
#include <utility>

#include <epoxy/gl.h>

#include "gpu/gl_context.h"
#include "gpu/gpu_counts.h"

namespace morphoflow {

namespace {
size_t live = 0, peak = 0;
}  // namespace

size_t GpuBuffer::liveBytes() { return live; }
size_t GpuBuffer::peakBytes() { return peak; }

GpuBuffer::GpuBuffer(size_t bytes, const void* data) : bytes_(bytes) {
  GlContext::instance();  // every GPU object starts with a buffer: the context exists from here
  glCreateBuffers(1, &id_);
  // At least one word: GL refuses empty storage.
  glNamedBufferStorage(id_, GLsizeiptr(bytes ? bytes : 4), data, GL_DYNAMIC_STORAGE_BIT);
  GlContext::check("allocating a GPU buffer");
  live += bytes_;
  peak = std::max(peak, live);
}

GpuBuffer& GpuBuffer::operator=(GpuBuffer&& o) noexcept {
  std::swap(id_, o.id_);
  std::swap(bytes_, o.bytes_);
  return *this;
}

GpuBuffer::~GpuBuffer() {
  if (!id_) return;
  glDeleteBuffers(1, &id_);
  live -= bytes_;
}

void GpuBuffer::upload(const void* data, size_t bytes, size_t offset) {
  if (bytes == 0) return;
  glNamedBufferSubData(id_, GLintptr(offset), GLsizeiptr(bytes), data);
  GlContext::check("writing a GPU buffer");
}

void GpuBuffer::download(void* data, size_t bytes, size_t offset) const {
  if (bytes == 0) return;
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(id_, GLintptr(offset), GLsizeiptr(bytes), data);
  countHostWait();
  GlContext::check("reading a GPU buffer");
}

void GpuBuffer::zero() {
  glClearNamedBufferData(id_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
}

void GpuBuffer::copyFrom(const GpuBuffer& src, size_t bytes, size_t srcOffset, size_t dstOffset) {
  if (bytes == 0) return;
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glCopyNamedBufferSubData(src.id_, id_, GLintptr(srcOffset), GLintptr(dstOffset), GLsizeiptr(bytes));
}

void GpuBuffer::bind(int binding) const { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, GLuint(binding), id_); }

}  // namespace morphoflow
