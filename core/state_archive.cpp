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

size_t StateWriter::serialisedSize() const {
  size_t n = 0;
  for (const auto& [name, data] : sections_) n += sizeof(uint32_t) + name.size() + sizeof(uint64_t) + data.size();
  return n;
}

void StateWriter::serialiseInto(std::string* out) {
  out->reserve(out->size() + serialisedSize());
  for (auto& [name, data] : sections_) {
    append<uint32_t>(out, uint32_t(name.size()));
    *out += name;
    append<uint64_t>(out, uint64_t(data.size()));
    *out += data;
    std::string().swap(data);
  }
  sections_.clear();
}

std::string StateWriter::serialise() const {
  std::string out;
  out.reserve(serialisedSize());
  for (const auto& [name, data] : sections_) {
    append<uint32_t>(&out, uint32_t(name.size()));
    out += name;
    append<uint64_t>(&out, uint64_t(data.size()));
    out += data;
  }
  return out;
}

StateReader::StateReader(const std::string& in) {
  size_t at = 0;
  while (at < in.size()) {
    const uint32_t n = take<uint32_t>(in, &at);
    if (in.size() - at < n) throw StateError("the state ends inside a section name");
    std::string name = in.substr(at, n);
    at += n;
    const uint64_t bytes = take<uint64_t>(in, &at);
    if (in.size() - at < bytes) throw StateError("section '" + name + "' is cut short");
    sections_[name] = in.substr(at, bytes);
    at += bytes;
  }
}

const std::string& StateReader::bytes(const std::string& name, size_t expected) const {
  auto it = sections_.find(name);
  if (it == sections_.end()) throw StateError("the state has no section '" + name + "'");
  if (it->second.size() != expected)
    throw StateError("section '" + name + "' holds " + std::to_string(it->second.size()) + " bytes, expected " +
                     std::to_string(expected));
  return it->second;
}

}  // namespace morphoflow
