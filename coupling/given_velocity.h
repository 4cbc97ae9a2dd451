// Given velocity fields (flow visualisation, seed 004 sec. 3 and fig. 24): the
// ARD layer carried by a velocity that no fluid solver computes, either
// analytic expressions in x, y, z (domain units) and t, or a sequence of
// OpenVDB volumes written by another solver (or by morphoflow), resampled to
// the chemical grid's MAC faces and interpolated linearly in time between
// frames. Before the first frame the first holds, after the last the last.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/expression.h"
#include "core/mac_velocity.h"

namespace morphoflow {

template <int D>
class GivenVelocity {
 public:
  virtual ~GivenVelocity() = default;
  // The velocity at time t, domain units per time unit, on u's faces (u
  // sized for the chemical grid); a source with a grid of its own over the
  // same domain may reshape u to it (the advection samples it in world space).
  virtual void sample(double t, MacVelocity<D>* u) = 0;
  // True when sample() gives the same field at every time.
  virtual bool steady() const = 0;
};

// On a periodic axis face n duplicates face 0: copies it there.
template <int D>
void wrapPeriodicFaces(MacVelocity<D>* u);

// One expression per axis in the variables x, y, z, t.
template <int D>
class ExpressionVelocity : public GivenVelocity<D> {
 public:
  // Throws ExpressionError (with the component in `component`) for a malformed expression.
  explicit ExpressionVelocity(const std::vector<std::string>& expressions);
  void sample(double t, MacVelocity<D>* u) override;
  bool steady() const override { return steady_; }
  static const std::vector<std::string>& variables();

 private:
  std::vector<Expression> components_;
  bool steady_ = true;
};

// One frame of a VDB velocity sequence.
struct VelocityFrame {
  std::string path;
  double time = 0.0;
};

// Thrown when a frame cannot be read or does not fit the domain.
class VelocityFileError : public std::runtime_error {
 public:
  VelocityFileError(std::string path, const std::string& message)
      : std::runtime_error(message), path_(std::move(path)) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// What to do about a VelocityFileError, for a scene's message.
inline constexpr const char* kVelocityFilesHint =
    "give a sequence of .vdb files with a Vec3 grid 'vel' over the scene's domain, e.g. written by `morphoflow run` "
    "with output.vdb = true";

// The frames of `pattern` (a path whose run of '#' stands for the frame
// number, zero-padded to its length, or one file), in frame order. A frame's
// time is its `time` metadata, or frame number x frameTime when the file has
// none (frameTime <= 0: such a file is an error). Throws VelocityFileError.
std::vector<VelocityFrame> findVelocityFrames(const std::string& pattern, double frameTime);

template <int D>
class VdbVelocitySequence : public GivenVelocity<D> {
 public:
  // `domain` is the scene's extent per axis; every frame must fill the same one.
  VdbVelocitySequence(std::vector<VelocityFrame> frames, const std::array<double, D>& domain);
  void sample(double t, MacVelocity<D>* u) override;
  bool steady() const override { return frames_.size() == 1; }

 private:
  const MacVelocity<D>& frame(size_t k, const MacVelocity<D>& like);

  std::vector<VelocityFrame> frames_;
  std::array<double, D> domain_;
  std::map<size_t, MacVelocity<D>> cache_;  // the frames last used, resampled to the chemical grid
};

}  // namespace morphoflow
