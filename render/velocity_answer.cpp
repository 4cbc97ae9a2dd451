#include "render/velocity_answer.h"

#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace morphoflow {

namespace {

// The answer, field by field.
template <class T>
void put(std::string* s, const T& v) {
  s->append(reinterpret_cast<const char*>(&v), sizeof v);
}
void putText(std::string* s, const std::string& t) {
  put<uint64_t>(s, t.size());
  s->append(t);
}
template <class T>
T take(const std::string& s, size_t* at) {
  if (s.size() - *at < sizeof(T)) throw std::runtime_error("the reader's answer is cut short");
  T v;
  std::memcpy(&v, s.data() + *at, sizeof v);
  *at += sizeof v;
  return v;
}
std::string takeText(const std::string& s, size_t* at) {
  const uint64_t n = take<uint64_t>(s, at);
  if (s.size() - *at < n) throw std::runtime_error("the reader's answer is cut short");
  std::string t = s.substr(*at, n);
  *at += n;
  return t;
}

}  // namespace

std::string encodeVelocityAnswer(bool ok, const VelocityVolume& v, const std::string& error) {
  std::string s;
  put<uint8_t>(&s, ok);
  if (!ok) {
    putText(&s, error);
    return s;
  }
  putText(&s, v.grid);
  put(&s, v.staggered), put(&s, v.origin), put(&s, v.cells), put(&s, v.voxelSize), put(&s, v.indexOrigin);
  put(&s, v.hasTime), put(&s, v.hasDomain), put(&s, v.time), put(&s, v.domain);
  for (const std::vector<float>& c : v.values)
    putText(&s,
            c.empty() ? std::string() : std::string(reinterpret_cast<const char*>(c.data()), c.size() * sizeof(float)));
  return s;
}

bool decodeVelocityAnswer(const std::string& s, VelocityVolume* v, std::string* error) try {
  size_t at = 0;
  if (!take<uint8_t>(s, &at)) {
    *error = takeText(s, &at);
    return false;
  }
  v->grid = takeText(s, &at);
  v->staggered = take<bool>(s, &at);
  v->origin = take<std::array<int, 3>>(s, &at);
  v->cells = take<std::array<int, 3>>(s, &at);
  v->voxelSize = take<double>(s, &at);
  v->indexOrigin = take<std::array<double, 3>>(s, &at);
  v->hasTime = take<bool>(s, &at);
  v->hasDomain = take<bool>(s, &at);
  v->time = take<double>(s, &at);
  v->domain = take<std::array<double, 3>>(s, &at);
  for (std::vector<float>& c : v->values) {
    const std::string b = takeText(s, &at);
    c.resize(b.size() / sizeof(float));
    if (!c.empty()) std::memcpy(c.data(), b.data(), c.size() * sizeof(float));
  }
  return true;
} catch (const std::exception& e) {
  *error = e.what();
  return false;
}

}  // namespace morphoflow
