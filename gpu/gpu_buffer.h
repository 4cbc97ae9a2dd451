// A GL shader storage buffer that owns its storage: allocated once, written
// and read whole or in part; every failure is a GpuError.
#pragma once

#include <cstddef>
#include <vector>

namespace morphoflow {

class GpuBuffer {
 public:
  GpuBuffer() = default;
  explicit GpuBuffer(size_t bytes, const void* data = nullptr);
  template <class T>
  static GpuBuffer of(const std::vector<T>& v) {
    return GpuBuffer(v.size() * sizeof(T), v.data());
  }
  GpuBuffer(GpuBuffer&& o) noexcept : id_(o.id_), bytes_(o.bytes_) { o.id_ = 0; }
  GpuBuffer& operator=(GpuBuffer&& o) noexcept;
  GpuBuffer(const GpuBuffer&) = delete;
  GpuBuffer& operator=(const GpuBuffer&) = delete;
  ~GpuBuffer();

  void upload(const void* data, size_t bytes, size_t offset = 0);
  template <class T>
  void upload(const std::vector<T>& v, size_t offset = 0) {
    upload(v.data(), v.size() * sizeof(T), offset);
  }
  // Waits for the queued work that writes the buffer.
  void download(void* data, size_t bytes, size_t offset = 0) const;
  template <class T>
  std::vector<T> read(size_t count, size_t offset = 0) const {
    std::vector<T> v(count);
    download(v.data(), count * sizeof(T), offset);
    return v;
  }
  void zero();
  void copyFrom(const GpuBuffer& src, size_t bytes, size_t srcOffset = 0, size_t dstOffset = 0);
  void bind(int binding) const;
  size_t bytes() const { return bytes_; }
  // The bytes of every buffer alive now, and at most so far, in this process (run.json's gpu.device_bytes).
  static size_t liveBytes();
  static size_t peakBytes();
  unsigned id() const { return id_; }

 private:
  unsigned id_ = 0;
  size_t bytes_ = 0;
};

}  // namespace morphoflow
