// WorkPool: work vectors that the stages of a step borrow in turn. A stage
// takes what it needs when it starts and gives it back when it ends, so the
// stages share one set of buffers (the largest stage's) instead of each
// keeping its own between steps. Vectors keep their capacity while pooled:
// after the first step nothing is allocated.
#pragma once

#include <algorithm>
#include <initializer_list>
#include <type_traits>
#include <utility>
#include <vector>

namespace morphoflow {

class WorkPool {
 public:
  // Gives an empty *v a pooled vector (the largest held; its contents are
  // unspecified), for a stage about to use v; leaves any other v alone.
  template <class T>
  void lend(std::vector<T>* v) {
    if (v->capacity() == 0) *v = take<T>();
  }
  // Moves *v's storage back into the pool, leaving v empty.
  template <class T>
  void give(std::vector<T>* v) {
    if (v->capacity() > 0) heldOf<T>().push_back(std::move(*v));
    *v = std::vector<T>();
  }
  // The same for a stage's set of vectors.
  template <class T>
  void lend(std::initializer_list<std::vector<T>*> vs) {
    for (std::vector<T>* v : vs) lend(v);
  }
  template <class T>
  void give(std::initializer_list<std::vector<T>*> vs) {
    for (std::vector<T>* v : vs) give(v);
  }

 private:
  template <class T>
  std::vector<T> take() {
    std::vector<std::vector<T>>& held = heldOf<T>();
    if (held.empty()) return {};
    auto most = std::max_element(held.begin(), held.end(),
                                 [](const auto& a, const auto& b) { return a.capacity() < b.capacity(); });
    std::vector<T> v = std::move(*most);
    held.erase(most);
    return v;
  }
  template <class T>
  std::vector<std::vector<T>>& heldOf() {
    if constexpr (std::is_same_v<T, float>)
      return floats_;
    else
      return doubles_;
  }
  std::vector<std::vector<float>> floats_;
  std::vector<std::vector<double>> doubles_;
};

}  // namespace morphoflow
