// A simulation's complete state as named binary sections, for checkpoints:
// a StateWriter streams the sections to a sink, a StateReader hands them
// back and checks that each one is there with the size the reader expects.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

class StateWriter {
 public:
  // Receives each section as it is put: its frame (name length, name and
  // size, as StateReader parses them), then its bytes. Nothing is held in
  // between, so a checkpoint streams a large state to its file uncopied.
  using Sink = std::function<void(std::string_view frame, const void* data, size_t bytes)>;
  explicit StateWriter(Sink sink) : sink_(std::move(sink)) {}

  void putBytes(const std::string& name, const void* data, size_t bytes);
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

 private:
  Sink sink_;
};

// Thrown for a missing section or one of the wrong size: the state was
// written by another scene or build.
class StateError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

class StateReader {
 public:
  // Parses the sections a StateWriter put, one after another, keeping
  // `bytes` (moved in) and pointing into it; throws StateError when they
  // are malformed.
  explicit StateReader(std::string bytes);
  StateReader(const StateReader&) = delete;  // sections_ points into all_
  StateReader& operator=(const StateReader&) = delete;
  std::string_view bytes(const std::string& name, size_t expected) const;
  // Floating-point values are checked finite as they are read: a state
  // holding NaN or infinity was not written by a run (runs stop at the
  // first non-finite field) and is refused with a StateError.
  template <class T>
  void get(const std::string& name, T* value) const {
    std::memcpy(value, bytes(name, sizeof(T)).data(), sizeof(T));
    checkFinite(name, value, 1);
  }
  // Fills v, whose size is already the expected one.
  template <class T>
  void getVector(const std::string& name, std::vector<T>* v) const {
    const std::string_view b = bytes(name, v->size() * sizeof(T));
    if (!b.empty()) std::memcpy(v->data(), b.data(), b.size());
    checkFinite(name, v->data(), v->size());
  }
  template <class T, int D>
  void getGrid(const std::string& name, Grid<T, D>* g) const {
    const std::string_view b = bytes(name, g->size() * sizeof(T));
    if (!b.empty()) std::memcpy(g->data(), b.data(), b.size());
    checkFinite(name, g->data(), g->size());
  }
  bool has(const std::string& name) const { return sections_.count(name) != 0; }

 private:
  template <class T>
  static void checkFinite(const std::string& name, const T* v, size_t n) {
    if constexpr (std::is_floating_point_v<T>) {
      for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(v[i]))
          throw StateError("section '" + name + "' holds a non-finite value at index " + std::to_string(i));
    }
  }

  std::string all_;
  std::map<std::string, std::string_view> sections_;
};

}  // namespace morphoflow
