// A simulation's complete state as named binary sections, for checkpoints:
// a StateWriter collects the sections, a StateReader hands them back and
// checks that each one is there with the size the reader expects.
#pragma once

#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

class StateWriter {
 public:
  void putBytes(const std::string& name, const void* data, size_t bytes) {
    sections_[name].assign(static_cast<const char*>(data), static_cast<const char*>(data) + bytes);
  }
  template <class T>
  void put(const std::string& name, const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    putBytes(name, &value, sizeof(T));
  }
  template <class T>
  void putVector(const std::string& name, const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    putBytes(name, v.data(), v.size() * sizeof(T));
  }
  template <class T, int D>
  void putGrid(const std::string& name, const Grid<T, D>& g) {
    putVector(name, g.values());
  }
  // The sections as one byte string (each: name length, name, size, bytes).
  std::string serialise() const;
  // The length serialise() would return.
  size_t serialisedSize() const;
  // Appends serialise()'s bytes to *out and empties the writer, freeing each
  // section once it is copied: the whole state is held once, not twice (a
  // checkpoint of a large run is the run's peak memory otherwise).
  void serialiseInto(std::string* out);

 private:
  std::map<std::string, std::string> sections_;
};

// Thrown for a missing section or one of the wrong size: the state was
// written by another scene or build.
class StateError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

class StateReader {
 public:
  // Parses serialise()'s output; throws StateError when it is malformed.
  explicit StateReader(const std::string& bytes);
  const std::string& bytes(const std::string& name, size_t expected) const;
  template <class T>
  void get(const std::string& name, T* value) const {
    std::memcpy(value, bytes(name, sizeof(T)).data(), sizeof(T));
  }
  // Fills v, whose size is already the expected one.
  template <class T>
  void getVector(const std::string& name, std::vector<T>* v) const {
    const std::string& b = bytes(name, v->size() * sizeof(T));
    if (!b.empty()) std::memcpy(v->data(), b.data(), b.size());
  }
  template <class T, int D>
  void getGrid(const std::string& name, Grid<T, D>* g) const {
    const std::string& b = bytes(name, g->size() * sizeof(T));
    if (!b.empty()) std::memcpy(g->data(), b.data(), b.size());
  }
  bool has(const std::string& name) const { return sections_.count(name) != 0; }

 private:
  std::map<std::string, std::string> sections_;
};

}  // namespace morphoflow
