#include "render/lit_volume.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/parallel.h"
#include "render/blackbody.h"
#include "render/colormap.h"
#include "render/volume_camera.h"

namespace morphoflow {

namespace {

using Rgb = std::array<double, 3>;

constexpr Rgb kKey = kKeyLight, kSky = kSkyLight;
constexpr double kCrispness = 1.0 / 120.0;  // extinctionPerLength's hundred-and-twentieth
// The exposure puts the plume's median radiance at kMiddle before the tone
// curve, or its 95th percentile at kHigh where that is lower (nothing blown out).
constexpr double kMiddle = 0.55, kHigh = 2.5;
constexpr int kBlock = 8;  // cells a side of the empty-space blocks

double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// The transmittance with Wrenninge's octaves of multiple scattering
// (a = 0.3, b = 1/2, three octaves): sum_i a^i exp(-b^i tau).
double scattered(double tau) { return std::exp(-tau) + 0.3 * std::exp(-0.5 * tau) + 0.09 * std::exp(-0.25 * tau); }

// The q-quantile of the values (0 when there are none), as the value at q of the sorted values.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto at = v.begin() + std::ptrdiff_t(double(v.size() - 1) * q);
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

// The extinction per unit of density per cell.
double extinctionScale(const Grid<float, 3>& rho) {
  return extinctionPerLength(densityQ90(rho.data(), rho.size()), std::max({rho.dim(0), rho.dim(1), rho.dim(2)}));
}

// Bilinear interpolation in plane `ia` of axis a at (pb, pc) along axes b, c.
double planeSample(const Grid<float, 3>& g, int a, int ia, double pb, double pc) {
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const double xb = std::clamp(pb, 0.0, double(g.dim(b) - 1)), xc = std::clamp(pc, 0.0, double(g.dim(c) - 1));
  const int ib = std::min(int(xb), std::max(0, g.dim(b) - 2)), ic = std::min(int(xc), std::max(0, g.dim(c) - 2));
  const double wb = g.dim(b) > 1 ? xb - ib : 0.0, wc = g.dim(c) > 1 ? xc - ic : 0.0;
  double v = 0;
  for (int k = 0; k < 4; ++k) {
    IVec<3> x;
    x[a] = ia;
    x[b] = std::min(ib + (k & 1), g.dim(b) - 1);
    x[c] = std::min(ic + (k >> 1), g.dim(c) - 1);
    const double w = ((k & 1) ? wb : 1.0 - wb) * ((k >> 1) ? wc : 1.0 - wc);
    if (w != 0) v += w * g(x);
  }
  return v;
}

// The optical depth (density x cell lengths) from each cell's centre to the
// box's side along `toward` (a unit vector), swept plane by plane along its
// dominant axis from the side it points to: a cell's depth is that of the
// point one plane nearer (bilinear in that plane) plus the trapezoid of the
// densities between them; light enters the box at the sides.
Grid<float, 3> depthToward(const Grid<float, 3>& rho, const V3& toward) {
  int a = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(toward[size_t(k)]) > std::abs(toward[size_t(a)])) a = k;
  const int b = (a + 1) % 3, c = (a + 2) % 3, na = rho.dim(a);
  const double step = 1.0 / std::abs(toward[size_t(a)]);
  const double ob = toward[size_t(b)] * step, oc = toward[size_t(c)] * step;
  const int dir = toward[size_t(a)] > 0 ? 1 : -1;
  Grid<float, 3> tau(rho.dims(), 0.0f);
  for (int s = 0; s < na; ++s) {
    const int ia = dir > 0 ? na - 1 - s : s;
    parallelFor(size_t(rho.dim(b)), [&](size_t jb) {
      for (int jc = 0; jc < rho.dim(c); ++jc) {
        IVec<3> x;
        x[a] = ia;
        x[b] = int(jb);
        x[c] = jc;
        const double own = std::max(0.0f, rho(x)), pb = double(jb) + ob, pc = jc + oc;
        const bool inside = s > 0 && pb >= -0.5 && pb <= rho.dim(b) - 0.5 && pc >= -0.5 && pc <= rho.dim(c) - 0.5;
        const double d = inside ? planeSample(tau, a, ia + dir, pb, pc) +
                                      0.5 * step * (std::max(0.0, planeSample(rho, a, ia + dir, pb, pc)) + own)
                                : 0.5 * step * own;
        tau(x) = float(d);
      }
    });
  }
  return tau;
}

// blackbodyColour tabulated every 10 K up to 20,000 K (hotter: its value
// there) and interpolated linearly, so that a frame does not integrate
// Planck's law once a cell.
class BlackbodyTable {
 public:
  BlackbodyTable() {
    for (int k = 0; k <= kSteps; ++k) table_.push_back(blackbodyColour(kStep * k));
  }
  Rgb operator()(double kelvin) const {
    const double x = std::clamp(kelvin / kStep, 0.0, double(kSteps));
    const int k = std::min(int(x), kSteps - 1);
    const double w = x - k;
    Rgb c;
    for (size_t j = 0; j < 3; ++j) c[j] = (1.0 - w) * table_[size_t(k)][j] + w * table_[size_t(k) + 1][j];
    return c;
  }

 private:
  static constexpr int kSteps = 2000;
  static constexpr double kStep = 10.0;
  std::vector<Rgb> table_;
};

// What a cell sends toward the camera per unit of its extinction (linear
// RGB), and its density: the ray march's one sample.
struct Radiance {
  float r, g, b, rho;
};

// Grid `f` at the centre of cell x of a grid of `n` cells over the same box.
double at(const Grid<float, 3>& f, const IVec<3>& n, const IVec<3>& x, size_t i) {
  if (f.dims() == n) return f[i];
  V3 p;
  for (int a = 0; a < 3; ++a) p[size_t(a)] = (x[a] + 0.5) * f.dim(a) / n[a];
  return sampleCells(f, p);
}

Grid<Radiance, 3> radiance(const LitVolume& v, double kappa, const V3& toKey) {
  const Grid<float, 3>& rho = *v.density;
  const IVec<3>& n = rho.dims();
  const Grid<float, 3> key = depthToward(rho, toKey), sky = depthToward(rho, V3{0, 1, 0});
  std::array<double, 2> range{0.0, 1.0};
  if (v.shown) range = valueRange(v.shown->data(), v.shown->size(), v.options);
  const double span = range[1] > range[0] ? range[1] - range[0] : 1.0;
  const BlackbodyTable planck;
  Grid<Radiance, 3> out(n, Radiance{0, 0, 0, 0});
  forEachCell<3>(n, [&](const IVec<3>& x, size_t i) {
    const double d = std::max(0.0f, rho[i]);
    if (d == 0) return;
    Rgb albedo{1.0, 1.0, 1.0};
    if (v.shown) {
      const double t = (at(*v.shown, n, x, i) - range[0]) / span;
      const Rgb8 c = v.options.palette(std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0);
      for (int k = 0; k < 3; ++k) albedo[size_t(k)] = srgbToLinear(c[size_t(k)]);
    }
    const double lit = scattered(kappa * key[i]), open = scattered(kappa * sky[i]);
    Rgb glow{0, 0, 0};
    if (v.temperature && v.emission > 0)
      glow = planck(kKelvinAtAmbient + kKelvinPerUnit * (at(*v.temperature, n, x, i) - v.ambientTemperature));
    Rgb r;
    for (int k = 0; k < 3; ++k)
      r[size_t(k)] =
          albedo[size_t(k)] * (kKey[size_t(k)] * lit + kSky[size_t(k)] * open) + v.emission * glow[size_t(k)];
    out[i] = Radiance{float(r[0]), float(r[1]), float(r[2]), float(d)};
  });
  return out;
}

Radiance sampleRadiance(const Grid<Radiance, 3>& f, const V3& p) {
  double s[4] = {0, 0, 0, 0};
  trilinearTaps(f.dims(), p, [&](const IVec<3>& k, double w) {
    const Radiance& q = f(k);
    s[0] += w * q.r;
    s[1] += w * q.g;
    s[2] += w * q.b;
    s[3] += w * q.rho;
  });
  return Radiance{float(s[0]), float(s[1]), float(s[2]), float(s[3])};
}

// Blocks of kBlock^3 cells holding density, grown by a block on every side,
// so that a sample in an empty block reads only zeros.
Grid<uint8_t, 3> occupiedBlocks(const Grid<float, 3>& rho) {
  IVec<3> nb;
  for (int a = 0; a < 3; ++a) nb[a] = (rho.dim(a) + kBlock - 1) / kBlock;
  Grid<uint8_t, 3> own(nb, 0), grown(nb, 0);
  for (size_t i = 0; i < rho.size(); ++i)
    if (rho[i] > 0) {
      const IVec<3> x = rho.coord(i);
      own(IVec<3>{x[0] / kBlock, x[1] / kBlock, x[2] / kBlock}) = 1;
    }
  forEachCell<3>(nb, [&](const IVec<3>& x, size_t i) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const IVec<3> y{x[0] + dx, x[1] + dy, x[2] + dz};
          if (own.contains(y) && own(y)) grown[i] = 1;
        }
  });
  return grown;
}

struct Pixel {
  Rgb c{0, 0, 0};
  Rgb surface{0, 0, 0};  // an obstacle's radiance, seen through the smoke before it
  double transmittance = 1.0;
  bool solid = false;  // the ray ended on an obstacle
};

// The obstacles' grid seen from the density's cell coordinates.
struct SolidView {
  const Grid<float, 3>* g = nullptr;
  V3 scale{1, 1, 1};
  double at(const V3& p) const { return sampleCells(*g, V3{p[0] * scale[0], p[1] * scale[1], p[2] * scale[2]}); }
  // The outward normal: down the solid's gradient.
  V3 normal(const V3& p) const {
    V3 grad{0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      V3 hi = p, lo = p;
      hi[size_t(a)] += 1.0 / scale[size_t(a)];
      lo[size_t(a)] -= 1.0 / scale[size_t(a)];
      grad[size_t(a)] = at(lo) - at(hi);
    }
    const double len = std::sqrt(grad[0] * grad[0] + grad[1] * grad[1] + grad[2] * grad[2]);
    return len > 0 ? scale3(grad, 1.0 / len) : V3{0, 1, 0};
  }
  static V3 scale3(const V3& v, double s) { return V3{v[0] * s, v[1] * s, v[2] * s}; }
};

// An obstacle's surface at p (normal n): grey, lit by the key and the sky.
Rgb solidRadiance(const V3& n, const V3& toKey) {
  const double key = std::max(0.0, n[0] * toKey[0] + n[1] * toKey[1] + n[2] * toKey[2]);
  const double sky = 0.5 + 0.5 * n[1];
  Rgb c;
  for (int k = 0; k < 3; ++k)
    c[size_t(k)] = kObstacleAlbedo * (kKeyLight[size_t(k)] * key + 4.0 * kSkyLight[size_t(k)] * sky);
  return c;
}

// Emission-absorption along the ray of the precomputed radiance, samples at
// t0 + (j + 1/2) ds; empty blocks are skipped without moving the samples.
Pixel march(const Grid<Radiance, 3>& f, const Grid<uint8_t, 3>& occupied, double kappa, const V3& eye, const V3& d,
            const SolidView& solid, const V3& toKey) {
  Pixel px;
  double t0, t1;
  if (!clipToBox(eye, d, f.dims(), &t0, &t1)) return px;
  constexpr double ds = 0.5;
  for (long j = 0;; ++j) {
    const double t = t0 + (double(j) + 0.5) * ds;
    if (t >= t1 || px.transmittance < 1e-3) break;
    const V3 p = add(eye, scale(d, t));
    IVec<3> blk;
    for (int a = 0; a < 3; ++a) blk[a] = std::clamp(int(p[size_t(a)]) / kBlock, 0, occupied.dim(a) - 1);
    if (!occupied(blk)) {
      // Leave the block: the first sample at or past its far side.
      double exit = t1;
      for (int a = 0; a < 3; ++a) {
        if (d[size_t(a)] == 0) continue;
        const double side = (blk[a] + (d[size_t(a)] > 0 ? 1 : 0)) * double(kBlock);
        exit = std::min(exit, (side - eye[size_t(a)]) / d[size_t(a)]);
      }
      j = std::max(j, long(std::ceil((exit - t0) / ds - 0.5)) - 1);
      continue;
    }
    if (solid.g && solid.at(p) >= 0.5) {  // an obstacle: its surface, found by bisection since the last sample
      double lo = t - ds, hi = t;
      for (int it = 0; it < 12; ++it) {
        const double mid = 0.5 * (lo + hi);
        (solid.at(add(eye, scale(d, mid))) >= 0.5 ? hi : lo) = mid;
      }
      const Rgb c = solidRadiance(solid.normal(add(eye, scale(d, hi))), toKey);
      for (int k = 0; k < 3; ++k) px.surface[size_t(k)] = px.transmittance * c[size_t(k)];
      px.transmittance = 0.0;
      px.solid = true;
      break;
    }
    const Radiance s = sampleRadiance(f, p);
    if (s.rho <= 0) continue;
    const double a = -std::expm1(-kappa * s.rho * ds), w = px.transmittance * a;
    px.c[0] += w * s.r;
    px.c[1] += w * s.g;
    px.c[2] += w * s.b;
    px.transmittance *= 1.0 - a;
  }
  return px;
}

uint8_t encode(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  return uint8_t(std::lround(255.0 * (v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055)));
}

}  // namespace

std::array<double, 3> keyLightDirection() {
  const VolumeCamera cam(IVec<3>{1, 1, 1});  // the camera's axes are the same for every box
  return unit(add(add(scale(cam.right, -0.8), V3{0, 1.1, 0}), scale(cam.towardEye, 0.4)));
}

double densityQ90(const float* values, size_t n) {
  float top = 0;
  for (size_t i = 0; i < n; ++i) top = std::max(top, values[i]);
  std::vector<double> v;
  for (size_t i = 0; i < n; ++i)
    if (values[i] > 1e-3f * top) v.push_back(values[i]);
  return quantile(std::move(v), 0.9);
}

double extinctionPerLength(double q90, double side) { return q90 > 0 ? 1.0 / (q90 * kCrispness * side) : 0.0; }

LitImage renderLitVolume(const LitVolume& v, int size) {
  const Grid<float, 3>& rho = *v.density;
  const VolumeCamera cam(rho.dims());
  const V3 toKey = keyLightDirection();
  LitImage img;
  img.size = size;
  img.extinction = extinctionScale(rho);
  const Grid<Radiance, 3> f = radiance(v, img.extinction, toKey);
  Grid<uint8_t, 3> occupied = occupiedBlocks(rho);
  SolidView solid;
  if (v.solid) {  // the blocks that hold an obstacle are marched too
    solid.g = v.solid;
    for (int a = 0; a < 3; ++a) solid.scale[size_t(a)] = double(v.solid->dim(a)) / rho.dim(a);
    Grid<float, 3> held(rho.dims(), 0.0f);
    for (size_t i = 0; i < held.size(); ++i) {
      const IVec<3> x = held.coord(i);
      held[i] = at(*v.solid, rho.dims(), x, i) > 0.0f ? 1.0f : 0.0f;
    }
    const Grid<uint8_t, 3> more = occupiedBlocks(held);
    for (size_t i = 0; i < occupied.size(); ++i) occupied[i] = occupied[i] || more[i];
  }
  std::vector<Pixel> px(size_t(size) * size_t(size));
  parallelFor(size_t(size), [&](size_t py) {
    for (int x = 0; x < size; ++x)
      px[py * size_t(size) + size_t(x)] =
          march(f, occupied, img.extinction, cam.eye, cam.ray(x, int(py), size), solid, toKey);
  });
  // The exposure, from the plume's own radiance (its pixels' colour over
  // their opacity, where that is at least a tenth; not an obstacle's).
  std::vector<double> seen;
  for (const Pixel& p : px)
    if (!p.solid && 1.0 - p.transmittance >= 0.1) seen.push_back(luminance(p.c) / (1.0 - p.transmittance));
  const double m = quantile(seen, 0.5), high = quantile(seen, 0.95);
  img.exposure = m > 0 ? std::min(kMiddle / m, kHigh / high) : 1.0;
  img.rgb.resize(px.size() * 3);
  img.opacity.resize(px.size());
  for (size_t i = 0; i < px.size(); ++i) {
    img.opacity[i] = float(1.0 - px[i].transmittance);
    for (int k = 0; k < 3; ++k)  // the tone curve 1 - exp(-x), over the background
      img.rgb[i * 3 + size_t(k)] =
          encode(-std::expm1(-img.exposure * px[i].c[size_t(k)] - kObstacleExposure * px[i].surface[size_t(k)]) +
                 px[i].transmittance * kBackdrop[size_t(k)]);
  }
  return img;
}

}  // namespace morphoflow
