#include "studio/frame_encoding.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <fmt/format.h>

namespace morphoflow {

namespace {

template <int D>
Grid<float, D> magnitude(const std::vector<Grid<float, D>>& field) {
  if (field.size() == 1) return field[0];
  Grid<float, D> m(field[0].dims(), 0.0f);
  for (size_t i = 0; i < m.size(); ++i) {
    double s = 0.0;
    for (const Grid<float, D>& g : field) s += double(g[i]) * double(g[i]);
    m[i] = float(std::sqrt(s));
  }
  return m;
}

// A 3D grid box-averaged by an integer factor per axis so that no side exceeds kFrameVolumeSide.
template <int D>
Grid<float, D> downsampled(const Grid<float, D>& g) {
  if constexpr (D == 2) {
    return g;
  } else {
    IVec<D> f, dims;
    for (int a = 0; a < D; ++a) {
      f[a] = (g.dims()[a] + kFrameVolumeSide - 1) / kFrameVolumeSide;
      dims[a] = g.dims()[a] / f[a];
    }
    if (f[0] == 1 && f[1] == 1 && f[2] == 1) return g;
    Grid<float, D> out(dims, 0.0f);
    for (size_t i = 0; i < out.size(); ++i) {
      const IVec<D> c = out.coord(i);
      double s = 0.0;
      for (int z = 0; z < f[2]; ++z)
        for (int y = 0; y < f[1]; ++y)
          for (int x = 0; x < f[0]; ++x) s += g(IVec<D>{c[0] * f[0] + x, c[1] * f[1] + y, c[2] * f[2] + z});
      out[i] = float(s / double(f[0] * f[1] * f[2]));
    }
    return out;
  }
}

void putU32(std::string* out, uint32_t v) {
  for (int k = 0; k < 4; ++k) out->push_back(char((v >> (8 * k)) & 0xff));
}

}  // namespace

template <int D>
std::string encodeFrame(const std::vector<Grid<float, D>>& field, const Palette& palette, bool autoRange,
                        const double range[2], bool symmetric, nlohmann::json meta) {
  // The values shown: the field itself (one component, a grid small enough),
  // else its magnitude and box average, made once.
  Grid<float, D> made;
  const Grid<float, D>* shown = &field.front();
  if (field.size() > 1) made = magnitude<D>(field), shown = &made;
  if (D == 3) made = downsampled<D>(*shown), shown = &made;
  const Grid<float, D>& g = *shown;
  double lo = range[0], hi = range[1];
  if (autoRange) {
    float l = std::numeric_limits<float>::infinity(), u = -l;
    for (float v : g.values()) l = std::min(l, v), u = std::max(u, v);
    lo = l <= u ? l : 1e300, hi = l <= u ? u : -1e300;  // (no number: the empty range)
    if (symmetric) hi = std::max(std::abs(lo), std::abs(hi)), lo = -hi;
  }
  if (!(hi > lo)) hi = lo + 1.0;
  std::vector<int> dims;
  for (int a = 0; a < D; ++a) dims.push_back(g.dims()[a]);
  meta["dims"] = dims;
  meta["range"] = {lo, hi};
  const std::string header = meta.dump();
  std::string out = "MFF1";
  putU32(&out, uint32_t(header.size()));
  out += header;
  for (int k = 0; k < 256; ++k) {
    const Rgb8 c = palette(k / 255.0);
    out.append(reinterpret_cast<const char*>(c.data()), 3);
  }
  const size_t at = out.size();
  out.resize(at + g.size());
  const double scale = 255.0 / (hi - lo);
  for (size_t i = 0; i < g.size(); ++i) {
    const double v = (double(g[i]) - lo) * scale;
    out[at + i] = char(uint8_t(std::isfinite(v) ? std::clamp(v + 0.5, 0.0, 255.0) : 0.0));
  }
  return out;
}

template <int D>
std::string npyFile(const std::vector<Grid<float, D>>& field) {
  std::vector<size_t> shape;
  if (field.size() > 1) shape.push_back(field.size());
  for (int a = D - 1; a >= 0; --a) shape.push_back(size_t(field[0].dims()[a]));
  std::string dict = fmt::format("{{'descr': '<f4', 'fortran_order': False, 'shape': ({}{}), }}",
                                 fmt::join(shape, ", "), shape.size() == 1 ? "," : "");
  // Magic, version 1.0, header length; the header padded with spaces to a multiple of 64 and ended by '\n'.
  const size_t total = (10 + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - 10 - dict.size() - 1, ' ');
  dict += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(char(dict.size() & 0xff));
  out.push_back(char(dict.size() >> 8));
  out += dict;
  for (const Grid<float, D>& g : field) {
    static_assert(sizeof(float) == 4);
    out.append(reinterpret_cast<const char*>(g.data()), g.size() * sizeof(float));
  }
  return out;
}

template std::string encodeFrame<2>(const std::vector<Grid<float, 2>>&, const Palette&, bool, const double[2], bool,
                                    nlohmann::json);
template std::string encodeFrame<3>(const std::vector<Grid<float, 3>>&, const Palette&, bool, const double[2], bool,
                                    nlohmann::json);
template std::string npyFile<2>(const std::vector<Grid<float, 2>>&);
template std::string npyFile<3>(const std::vector<Grid<float, 3>>&);

}  // namespace morphoflow
