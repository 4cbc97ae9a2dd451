// WorkPool: work vectors that the stages of a step borrow in turn. A stage
// takes what it needs when it starts and gives it back when it ends, so the
// stages share one set of buffers (the largest stage's) instead of each
// keeping its own between steps. Vectors keep their capacity while pooled:
// after the first step nothing is allocated.
#pragma once

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace morphoflow {

// v->resize(n, value), allocating exactly n where v must grow (a resize past
// the capacity doubles it): for the vectors a WorkPool lends, whose
// capacity a stage of another shape may have set.
template <class T>
void resizeExactly(std::vector<T>* v, size_t n, T value = T()) {
  if (v->capacity() < n) v->reserve(n);
  v->resize(n, value);
}

class WorkPool {
 public:
  // Gives an empty *v a pooled vector (the largest held; its contents are
  // unspecified), for a stage about to use v; leaves any other v alone.
  template <class T>
  void lend(std::vector<T>* v) {
    lend(v, 0);
  }
  // The same for a v that will hold n elements: the smallest held vector
  // with room for them (else the largest), so that a field kept between
  // steps does not keep a larger stage's vector.
  //
  // A vector lent holds room for the largest size its type was given back
  // at where it is within half of it (a face grid's against a cell grid's,
  // a colour's half): it is replaced by one that large, so that no stage's
  // resize grows it (which would double it, or copy it). A vector of
  // another grid (a finer layer's, sharing the pool) is left as it is.
  template <class T>
  void lend(std::vector<T>* v, size_t n) {
    if (v->capacity() > 0) return;
    *v = take<T>(n);  // (none: v stays empty, to be sized by the stage)
    const size_t most = mostOf<T>();
    if (v->capacity() > 0 && v->capacity() < most && 2 * v->capacity() >= most) {
      *v = std::vector<T>();  // (freed before the larger one is made)
      *v = reserved<T>(most);
    }
  }
  // Moves *v's storage back into the pool, leaving v empty. One that a
  // stage's resize grew past the largest size any was given back at (a
  // resize past the capacity doubles it: a cell-sized vector lent for a
  // face-sized field would hold twice the cells) keeps room for that size
  // alone; resizeExactly grows one without doubling.
  template <class T>
  void give(std::vector<T>* v) {
    if (v->capacity() > 0) {
      size_t& most = mostOf<T>();
      most = std::max(most, v->size());
      if (v->capacity() > most) {
        *v = std::vector<T>();  // (freed before the smaller one is made)
        *v = reserved<T>(most);
      }
      heldOf<T>().push_back(std::move(*v));
    }
    *v = std::vector<T>();
  }
  // A stage used n elements of a vector it gives back (beyond its size()).
  template <class T>
  void used(size_t n) {
    mostOf<T>() = std::max(mostOf<T>(), n);
  }
  // The bytes the pool holds (its vectors' capacities).
  size_t bytes() const {
    size_t b = 0;
    for (const auto& v : floats_) b += v.capacity() * sizeof(float);
    for (const auto& v : doubles_) b += v.capacity() * sizeof(double);
    return b;
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
  // The smallest held vector with room for n, else the largest.
  template <class T>
  std::vector<T> take(size_t n) {
    std::vector<std::vector<T>>& held = heldOf<T>();
    if (held.empty()) return {};
    auto better = [n](const std::vector<T>& a, const std::vector<T>& b) {  // a fits n worse than b
      const bool fa = a.capacity() >= n && n > 0, fb = b.capacity() >= n && n > 0;
      if (fa != fb) return fb;
      return fa ? a.capacity() > b.capacity() : a.capacity() < b.capacity();
    };
    auto best = std::max_element(held.begin(), held.end(), better);
    std::vector<T> v = std::move(*best);
    held.erase(best);
    return v;
  }
  template <class T>
  static std::vector<T> reserved(size_t n) {  // (capacity n, no elements)
    std::vector<T> v;
    v.reserve(n);
    return v;
  }
  template <class T>
  size_t& mostOf() {
    return std::is_same_v<T, float> ? mostFloats_ : mostDoubles_;
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
  size_t mostFloats_ = 0, mostDoubles_ = 0;  // the largest sizes given back
};

// Float work arrays lent from a pool's vectors of either type: its double
// vectors (two arrays to one where they fit) and its float vectors, in the
// order the stage asks for (the one its typed vectors need less). A stage
// whose work is in floats (the advection's) so borrows the bytes the solves'
// double vectors hold while those are idle, instead of the pool keeping
// float vectors of its own beside them. Where the pool has too little, new
// double vectors are made (and kept by the pool).
class FloatArrays {
 public:
  FloatArrays() = default;
  FloatArrays(const FloatArrays&) = delete;
  FloatArrays& operator=(const FloatArrays&) = delete;
  FloatArrays(FloatArrays&&) = default;
  FloatArrays& operator=(FloatArrays&&) = default;
  ~FloatArrays() {
    WorkPool none;
    give(&none);
  }

  enum class First { Doubles, Floats };
  // k arrays of n floats each (contents unspecified), until give().
  void lend(WorkPool* pool, int k, size_t n, First first = First::Doubles) {
    give(pool);
    if (first == First::Floats) fromFloats(pool, k, n);
    fromDoubles(pool, k, n, false);
    fromFloats(pool, k, n);
    fromDoubles(pool, k, n, true);
  }
  // Gives the vectors back to `pool` (the double vectors' elements doubles
  // again).
  void give(WorkPool* pool) {
    for (std::vector<float>& v : floats_) pool->give(&v);
    for (size_t k = 0; k < doubles_.size(); ++k) {
      std::vector<double>& v = doubles_[k];
      ::new (static_cast<void*>(v.data())) double[v.size()];
      pool->used<double>(carved_[k]);
      pool->give(&v);
    }
    floats_.clear();
    doubles_.clear();
    carved_.clear();
    arrays_.clear();
  }
  float* operator[](size_t i) const { return arrays_[i]; }
  size_t size() const { return arrays_.size(); }

 private:
  // Whole float vectors, while the pool has them.
  void fromFloats(WorkPool* pool, int k, size_t n) {
    while (int(arrays_.size()) < k) {
      std::vector<float> v;
      pool->lend(&v, n);
      if (v.capacity() < n || n == 0) {
        pool->give(&v);
        break;
      }
      v.resize(n);
      arrays_.push_back(v.data());
      floats_.push_back(std::move(v));
    }
  }
  // Double vectors, while the pool has them large enough, or (allocate)
  // new ones.
  void fromDoubles(WorkPool* pool, int k, size_t n, bool allocate) {
    const size_t doubles = (n + 1) / 2;  // one array's bytes, in doubles
    while (int(arrays_.size()) < k) {
      const int left = k - int(arrays_.size());
      std::vector<double> v;
      if (allocate) {
        v.reserve(doubles * size_t(std::min(left, 2)));
      } else {
        pool->lend(&v, doubles * size_t(std::min(left, 2)));
        if (v.capacity() < doubles) {
          pool->give(&v);
          return;
        }
      }
      if (v.empty()) v.resize(1);  // (data() is then the storage's start)
      // The storage's bytes hold floats now: their lifetime begins here,
      // the doubles' ends (both trivial: no code). give() restores them.
      const size_t fit = std::min(size_t(left), v.capacity() / doubles);
      float* f = ::new (static_cast<void*>(v.data())) float[fit * doubles * 2];
      for (size_t j = 0; j < fit; ++j) arrays_.push_back(f + j * doubles * 2);
      doubles_.push_back(std::move(v));
      carved_.push_back(fit * doubles);
    }
  }

  std::vector<std::vector<float>> floats_;
  std::vector<std::vector<double>> doubles_;
  std::vector<size_t> carved_;  // the doubles' worth each holds
  std::vector<float*> arrays_;
};

}  // namespace morphoflow
