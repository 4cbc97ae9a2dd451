#include "core/state_archive.h"

namespace morphoflow {

namespace {

template <class T>
void append(std::string* out, T v) {
  out->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
T take(const std::string& in, size_t* at) {
  if (in.size() - *at < sizeof(T)) throw StateError("the state ends inside a section header");
  T v;
  std::memcpy(&v, in.data() + *at, sizeof(T));
  *at += sizeof(T);
  return v;
}

}  // namespace

void StateWriter::putBytes(const std::string& name, const void* data, size_t bytes) {
  std::string frame;
  append<uint32_t>(&frame, uint32_t(name.size()));
  frame += name;
  append<uint64_t>(&frame, uint64_t(bytes));
  sink_(frame, data, bytes);
}

StateReader::StateReader(std::string in) : all_(std::move(in)) {
  size_t at = 0;
  while (at < all_.size()) {
    const uint32_t n = take<uint32_t>(all_, &at);
    if (all_.size() - at < n) throw StateError("the state ends inside a section name");
    std::string name = all_.substr(at, n);
    at += n;
    const uint64_t bytes = take<uint64_t>(all_, &at);
    if (all_.size() - at < bytes) throw StateError("section '" + name + "' is cut short");
    sections_[name] = std::string_view(all_).substr(at, bytes);
    at += bytes;
  }
}

std::string_view StateReader::bytes(const std::string& name, size_t expected) const {
  auto it = sections_.find(name);
  if (it == sections_.end()) throw StateError("the state has no section '" + name + "'");
  if (it->second.size() != expected)
    throw StateError("section '" + name + "' holds " + std::to_string(it->second.size()) + " bytes, expected " +
                     std::to_string(expected));
  return it->second;
}

}  // namespace morphoflow
