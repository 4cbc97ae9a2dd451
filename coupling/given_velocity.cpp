#include "coupling/given_velocity.h"

#include "core/sampling.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/parallel.h"
#include "render/vdb_volume.h"

namespace morphoflow {

// On a periodic axis face n duplicates face 0.
template <int D>
void wrapPeriodicFaces(MacVelocity<D>* u) {
  for (int a = 0; a < D; ++a) {
    if (!u->periodic()[size_t(a)]) continue;
    Grid<float, D>& g = (*u)[a];
    for (size_t i = 0; i < g.size(); ++i) {
      IVec<D> c = g.coord(i);
      if (c[a] != u->cells()[a]) continue;
      c[a] = 0;
      g[i] = g(c);
    }
  }
}

template <int D>
const std::vector<std::string>& ExpressionVelocity<D>::variables() {
  static const std::vector<std::string> v{"x", "y", "z", "t"};
  return v;
}

template <int D>
ExpressionVelocity<D>::ExpressionVelocity(const std::vector<std::string>& expressions) {
  for (const std::string& e : expressions) {
    components_.emplace_back(e, variables());
    try {  // compiles without t: the field does not change in time
      Expression(e, {"x", "y", "z"});
    } catch (const ExpressionError&) {
      steady_ = false;
    }
  }
}

template <int D>
void ExpressionVelocity<D>::sample(double t, MacVelocity<D>* u) {
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    const Expression& e = components_[size_t(a)];
    forEachCell<D>(g.dims(), [&](const IVec<D>& k, size_t i) {
      const Vec<D> p = u->layout(a).toWorld(k);  // face k of component a: (k + 1/2 - e_a / 2) h
      const double v[4] = {p[0], p[1], D == 3 ? p[D - 1] : 0.0, t};
      g[i] = float(e.evaluate(v));
    });
  }
  wrapPeriodicFaces<D>(u);
}

std::vector<VelocityFrame> findVelocityFrames(const std::string& pattern, double frameTime) {
  namespace fs = std::filesystem;
  std::vector<std::pair<long, std::string>> files;
  const size_t hash = pattern.find('#');
  if (hash == std::string::npos) {
    if (!fs::is_regular_file(pattern)) throw VelocityFileError(pattern, "no such file");
    files.push_back({0, pattern});
  } else {
    const size_t end = pattern.find_first_not_of('#', hash);
    const size_t digits = (end == std::string::npos ? pattern.size() : end) - hash;
    const fs::path head(pattern.substr(0, hash));
    const fs::path dir = head.parent_path().empty() ? fs::path(".") : head.parent_path();
    const std::string prefix = head.filename().string();
    const std::string suffix = end == std::string::npos ? "" : pattern.substr(end);
    if (suffix.find('/') != std::string::npos)
      throw VelocityFileError(pattern, "the frame number ('#') must be in the file name");
    if (digits > 18)
      throw VelocityFileError(pattern,
                              std::to_string(digits) + " '#' make a frame number too long to count: use at most 18");
    std::error_code ec;
    fs::directory_iterator it(dir, ec);
    if (ec) throw VelocityFileError(pattern, "cannot list the folder " + dir.string() + ": " + ec.message());
    for (const fs::directory_entry& e : it) {
      const std::string name = e.path().filename().string();
      if (name.size() != prefix.size() + digits + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
        continue;
      const std::string number = name.substr(prefix.size(), digits);
      if (!std::all_of(number.begin(), number.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
      files.push_back({std::stol(number), e.path().string()});
    }
    if (files.empty())
      throw VelocityFileError(pattern, "no file matches (each '#' stands for one digit of the frame number)");
    std::sort(files.begin(), files.end());
  }
  std::vector<std::string> paths;
  for (const auto& file : files) paths.push_back(file.second);
  std::vector<VdbTime> times;
  size_t failed = 0;
  std::string err;
  const bool read = readVdbTimes(paths, &times, &failed, &err);
  std::vector<VelocityFrame> frames;
  for (size_t i = 0; i < times.size(); ++i) {  // the files before one that cannot be read first
    const auto& [number, path] = files[i];
    VelocityFrame f;
    f.path = path;
    f.time = times[i].time;
    if (!times[i].has) {
      if (!(frameTime > 0))
        throw VelocityFileError(
            path, "the file has no 'time' metadata, so the frame's time is unknown; give velocity.frame_time");
      f.time = double(number) * frameTime;
    }
    if (!frames.empty() && !(f.time > frames.back().time))
      throw VelocityFileError(path, "its time (" + std::to_string(f.time) + ") does not follow the previous frame's (" +
                                        std::to_string(frames.back().time) + ")");
    frames.push_back(f);
  }
  if (!read) throw VelocityFileError(paths[std::min(failed, paths.size() - 1)], err);
  return frames;
}

template <int D>
VdbVelocitySequence<D>::VdbVelocitySequence(std::vector<VelocityFrame> frames, const std::array<double, D>& domain)
    : frames_(std::move(frames)), domain_(domain) {}

namespace {

// A VDB velocity resampled (multilinearly; exactly where voxels and faces coincide) onto u's faces.
template <int D>
void resample(const VelocityVolume& v, MacVelocity<D>* u) {
  auto value = [&](int comp, const std::array<long, 3>& c) -> double {
    for (int b = 0; b < 3; ++b)
      if (c[size_t(b)] < 0 || c[size_t(b)] >= v.cells[size_t(b)]) return 0.0;  // inactive: the background
    return v
        .values[size_t(comp)][(size_t(c[2]) * size_t(v.cells[1]) + size_t(c[1])) * size_t(v.cells[0]) + size_t(c[0])];
  };
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    forEachCell<D>(g.dims(), [&](const IVec<D>& k, size_t i) {
      const Vec<D> p = u->layout(a).toWorld(k);  // face k of component a: (k + 1/2 - e_a / 2) h
      // Continuous index into the box; a staggered component a sits half a voxel lower along a.
      std::array<long, 3> c0{0, 0, 0};
      std::array<double, 3> w{0, 0, 0};
      for (int b = 0; b < D; ++b) {
        double gi = (p[b] - v.indexOrigin[size_t(b)]) / v.voxelSize + (v.staggered && b == a ? 0.5 : 0.0);
        if (std::abs(gi - std::round(gi)) < 1e-9) gi = std::round(gi);
        gi = boundedCoordinate(gi - v.origin[size_t(b)]);  // (a transform far from the domain: beyond the box)
        c0[size_t(b)] = long(std::floor(gi));
        w[size_t(b)] = gi - double(c0[size_t(b)]);
      }
      if (D == 2) c0[2] = -v.origin[2];  // a 2D field is the layer at index z = 0
      double s = 0;
      for (int corner = 0; corner < (1 << D); ++corner) {
        double weight = 1;
        std::array<long, 3> c = c0;
        for (int b = 0; b < D; ++b) {
          const bool hi = (corner >> b) & 1;
          weight *= hi ? w[size_t(b)] : 1.0 - w[size_t(b)];
          c[size_t(b)] += hi;
        }
        if (weight != 0.0) s += weight * value(a, c);
      }
      g[i] = float(s);
    });
  }
  wrapPeriodicFaces<D>(u);
}

}  // namespace

template <int D>
const MacVelocity<D>& VdbVelocitySequence<D>::frame(size_t k, const MacVelocity<D>& like) {
  if (auto it = cache_.find(k); it != cache_.end()) return it->second;
  const std::string& path = frames_[k].path;
  VelocityVolume v;
  std::string err;
  if (!readVdbVelocity(path, &v, &err)) throw VelocityFileError(path, err);
  if (v.hasDomain) {
    for (int a = 0; a < D; ++a)
      if (std::abs(v.domain[size_t(a)] - domain_[size_t(a)]) > 1e-6 * domain_[size_t(a)])
        throw VelocityFileError(path, "the volume was written for a domain of size " + std::to_string(v.domain[0]) +
                                          " x " + std::to_string(v.domain[1]) +
                                          (D == 3 ? " x " + std::to_string(v.domain[2]) : "") + ", not the scene's " +
                                          std::to_string(domain_[0]) + " x " + std::to_string(domain_[1]) +
                                          (D == 3 ? " x " + std::to_string(domain_[2]) : ""));
  } else {
    for (int a = 0; a < D; ++a) {  // a foreign file: its active voxels must lie in the domain
      const double lo = v.indexOrigin[size_t(a)] + (v.origin[size_t(a)] - 0.5) * v.voxelSize;
      const double hi = lo + v.cells[size_t(a)] * v.voxelSize;
      if (v.cells[size_t(a)] > 0 && (lo < -v.voxelSize || hi > domain_[size_t(a)] + 2 * v.voxelSize))
        throw VelocityFileError(path, "the velocity's active voxels reach from " + std::to_string(lo) + " to " +
                                          std::to_string(hi) + " along " + "xyz"[a] +
                                          ", outside the scene's domain [0, " + std::to_string(domain_[size_t(a)]) +
                                          "]");
    }
  }
  if (cache_.size() >= 2) cache_.erase(cache_.begin()->first < k ? cache_.begin() : std::prev(cache_.end()));
  // A staggered grid of cubes that tile the domain (as morphoflow writes it)
  // is kept on its own faces, exactly, and sampled by the advection as a
  // coupled run samples its fluid; anything else is resampled to `like`.
  IVec<D> native;
  bool exact = v.staggered;
  for (int a = 0; a < D; ++a) {
    const double n = domain_[size_t(a)] / v.voxelSize;
    native[a] = int(std::lround(n));
    exact &= native[a] > 0 && std::abs(n - native[a]) < 1e-6 * n &&
             std::abs(v.indexOrigin[size_t(a)] - 0.5 * v.voxelSize) < 1e-6 * v.voxelSize;
  }
  MacVelocity<D> u = exact ? MacVelocity<D>(native, domain_[0] / native[0], like.periodic())
                           : MacVelocity<D>(like.cells(), like.h(), like.periodic());
  resample<D>(v, &u);
  return cache_.emplace(k, std::move(u)).first->second;
}

template <int D>
void VdbVelocitySequence<D>::sample(double t, MacVelocity<D>* u) {
  size_t k = 0;
  while (k + 1 < frames_.size() && frames_[k + 1].time <= t) ++k;
  const double t0 = frames_[k].time;
  const bool between = k + 1 < frames_.size() && t > t0;
  const double w = between ? (t - t0) / (frames_[k + 1].time - t0) : 0.0;
  if (w == 0.0) {
    *u = frame(k, *u);
    return;
  }
  const MacVelocity<D> f0 = frame(k, *u);  // a copy: loading the next frame may evict it
  const MacVelocity<D>& f1 = frame(k + 1, *u);
  if (f0.cells() != f1.cells())
    throw VelocityFileError(frames_[k + 1].path,
                            "its velocity grid differs from the previous frame's, so the two cannot be blended");
  *u = f0;
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < (*u)[a].size(); ++i) (*u)[a][i] = float((1.0 - w) * f0[a][i] + w * f1[a][i]);
}

template void wrapPeriodicFaces<2>(MacVelocity<2>*);
template void wrapPeriodicFaces<3>(MacVelocity<3>*);
template class ExpressionVelocity<2>;
template class ExpressionVelocity<3>;
template class VdbVelocitySequence<2>;
template class VdbVelocitySequence<3>;

}  // namespace morphoflow
