// A moving obstacle's geometry on the device, over the cells [lo, lo + box)
// that a move touched (box: the cells, or grid `axis`'s faces of them), with
// kernels/obstacle_shape.inc's and cut_fraction.inc's formulas, as ObstaclePlacement::moveTo and
// VelocityConstraints::move make it on the host:
// MODE_CELLS  solid: inside any obstacle; voxel: inside a staircase one
// MODE_FACES  the faces' fixed flags, prescribed values and open fractions
// MODE_FLUX   the solid's flux through the closed parts of the cells' faces (0 where all are closed)
// The obstacles are `bodies` records of 40 doubles (gpu/fluid/gpu_obstacles.cpp);
// the images' and sdfs' fields lie in `fields`, one after another.
layout(std430, binding = 0) readonly buffer Bodies { double body[]; };
layout(std430, binding = 1) buffer Solid { uint solid[]; };
layout(std430, binding = 2) buffer Voxel { uint voxel[]; };
layout(std430, binding = 3) buffer Fixed { uint fixedFace[]; };
layout(std430, binding = 4) buffer Value { float value[]; };
layout(std430, binding = 5) buffer Open { float open[]; };
layout(std430, binding = 6) buffer Flux { double solidFlux[]; };
layout(std430, binding = 7) readonly buffer Fields { float fields[]; };

uniform ivec3 cells, lo, box, periodic, velOff;
uniform ivec3 lowKind, highKind;  // the domain's sides: 0 neither, 1 wall, 2 inflow
uniform int axis, n, bodies, cutBodies;
uniform bool parabolic, openPerFace, exactSurface;  // exactSurface: no cut image (only a sign)
uniform double h, inflowMean;
uniform double domainSize[3];

#define B_SHAPE 0
#define B_VOXEL 1
#define B_CENTRE 2
#define B_RADIUS 5
#define B_HALF 6
#define B_ORIENTATION 9
#define B_WRAP 18
#define B_MOTION_CENTRE 21
#define B_VELOCITY 24
#define B_OMEGA 27
#define B_FIELD_AT 30  // an image's or sdf's: its first texel in fields, its size, threshold and invert
#define B_FIELD_W 31
#define B_FIELD_H 32
#define B_THRESHOLD 33
#define B_INVERT 34
#define STRIDE 40

#define OS_REAL double
#define OS_FN double
#define OS_VOID void
#define OS_IN3(name) double name[3]
#define OS_IN9(name) double name[9]
#define OS_OUT3(name) precise out double name[3]
#define OS_SQRT sqrt
#define OS_ABS abs
#define OS_TRUNC trunc
#define OS_LIT(v) v##lf
#define OS_PRECISE precise
#define OS_TEXEL(i) double(fields[fieldAt + (i)])
#define OS_FIELD_PARAM int fieldAt,
#define OS_FIELD_ARG fieldAt,
#include "obstacle_shape.inc"
double cfSurfaceDistance(double x[3]);
#define CF_REAL double
#define CF_FN double
#define CF_IN3(name) double name[3]
#define CF_SQRT sqrt
#define CF_ABS abs
#define CF_LIT(v) v##lf
#define CF_PRECISE precise
#define CF_DISTANCE(x) cfSurfaceDistance(x)
#define CF_SURFACE_PARAM
#define CF_SURFACE_ARG
#include "cut_fraction.inc"

void bodyArray(int o, int at, out double v[3]) {
  for (int a = 0; a < 3; ++a) v[a] = body[STRIDE * o + at + a];
}

// Obstacle o's signed distance at world x (obstacleDistance).
double bodyDistance(int o, double x[3]) {
  const int shape = int(body[STRIDE * o + B_SHAPE]);
  if (shape >= 3)
    return osFieldDistance(int(body[STRIDE * o + B_FIELD_AT]), shape, int(body[STRIDE * o + B_FIELD_W]),
                           int(body[STRIDE * o + B_FIELD_H]), body[STRIDE * o + B_THRESHOLD],
                           body[STRIDE * o + B_INVERT] != 0.0lf, x, domainSize);
  double centre[3], wrap[3], halfSize[3], orientation[9], q[3];
  bodyArray(o, B_CENTRE, centre);
  bodyArray(o, B_WRAP, wrap);
  bodyArray(o, B_HALF, halfSize);
  for (int a = 0; a < 9; ++a) orientation[a] = body[STRIDE * o + B_ORIENTATION + a];
  osBodyFrame(DIM, x, centre, domainSize, wrap, orientation, q);
  return osShapeDistance(shape, DIM, q, body[STRIDE * o + B_RADIUS], halfSize);
}

// The cut obstacles' least distance (CutSurface::distance).
double cfSurfaceDistance(double x[3]) {
  double d = 1e308lf;
  for (int o = 0; o < bodies; ++o)
    if (body[STRIDE * o + B_VOXEL] == 0.0lf) {
      double od = bodyDistance(o, x);
      d = od < d ? od : d;
    }
  return d;
}

// Component a of the velocity of the obstacle nearest x (CutSurface::velocity).
double bodyVelocity(int a, double x[3]) {
  int nearest = 0;
  double d = 1e308lf;
  for (int o = 0; o < bodies; ++o) {
    double od = bodyDistance(o, x);
    if (od < d) {
      d = od;
      nearest = o;
    }
  }
  double centre[3], wrap[3], motionCentre[3], v[3], w[3];
  bodyArray(nearest, B_CENTRE, centre);
  bodyArray(nearest, B_WRAP, wrap);
  bodyArray(nearest, B_MOTION_CENTRE, motionCentre);
  bodyArray(nearest, B_VELOCITY, v);
  bodyArray(nearest, B_OMEGA, w);
  precise double image[3];  // where the obstacle wraps, the point's image nearest its centre
  for (int b = 0; b < 3; ++b) image[b] = b < DIM ? x[b] : 0.0lf;
  for (int b = 0; b < DIM; ++b)
    if (wrap[b] != 0.0lf) image[b] = image[b] - domainSize[b] * osRound((x[b] - centre[b]) / domainSize[b]);
  return osRigidVelocity(a, DIM, image, motionCentre, v, w);
}

// The world position of face k of grid a (cell centres across it).
void facePosition(int a, ivec3 k, out double x[3]) {
  for (int b = 0; b < 3; ++b) x[b] = b < DIM ? (double(k[b]) + (b == a ? 0.0lf : 0.5lf)) * h : 0.0lf;
}

// The inflow's normal speed at x on a side of axis a (VelocityConstraints::inflowSpeed).
double inflowSpeed(int a, double x[3]) {
  precise double u = inflowMean;
  if (!parabolic) return u;
  for (int b = 0; b < DIM; ++b) {
    if (b == a || periodic[b] != 0) continue;
    double s = x[b] / (double(cells[b]) * h);
    precise double profile = 1.5lf * 4.0lf * s * (1.0lf - s);
    u = u * profile;
  }
  return u;
}

void main() {
  const int i = flatIndex();
  if (i >= n) return;
  const ivec3 k = lo + coordsOf(i, box);
#if defined(MODE_CELLS)
  double x[3];
  for (int b = 0; b < 3; ++b) x[b] = b < DIM ? (double(k[b]) + 0.5lf) * h : 0.0lf;
  bool inside = false, staircase = false;
  for (int o = 0; o < bodies; ++o)
    if (bodyDistance(o, x) < 0.0lf) {
      inside = true;
      staircase = staircase || body[STRIDE * o + B_VOXEL] != 0.0lf;
    }
  solid[indexOf(k, cells)] = inside ? 1u : 0u;
  voxel[indexOf(k, cells)] = staircase ? 1u : 0u;
#elif defined(MODE_FACES)
  // VelocityConstraints::constrainFace: held by a wall, an inflow or a solid, and the open fraction.
  ivec3 fd = cells;
  fd[axis] += 1;
  const int f = velOff[axis] + indexOf(k, fd);
  double x[3];
  facePosition(axis, k, x);
  uint held = 0u;
  float prescribed = 0.0;
  if (periodic[axis] == 0 && (k[axis] == 0 || k[axis] == cells[axis])) {
    const bool high = k[axis] == cells[axis];
    const int kind = high ? highKind[axis] : lowKind[axis];
    if (kind != 0) held = 1u;
    if (kind == 2) {
      const double speed = inflowSpeed(axis, x);
      prescribed = float(high ? -speed : speed);
    }
  }
  ivec3 below = k, above = k, same = k;  // the cells on either side; on a periodic axis face n is face 0
  below[axis] -= 1;
  if (periodic[axis] != 0 && below[axis] < 0) below[axis] += cells[axis];
  if (periodic[axis] != 0 && above[axis] >= cells[axis]) above[axis] -= cells[axis];
  if (periodic[axis] != 0 && same[axis] == cells[axis]) same[axis] = 0;
  const bool solidLo = below[axis] >= 0 && voxel[indexOf(below, cells)] != 0u;
  const bool solidHi = above[axis] < cells[axis] && voxel[indexOf(above, cells)] != 0u;
  float fraction = 1.0;
  if (solidLo || solidHi) fraction = 0.0;
  else if (cutBodies > 0) fraction = float(cfOpenFraction(DIM, axis, same.x, same.y, same.z, h, exactSurface));
  if (fraction == 0.0) {
    held = 1u;
    prescribed = float(bodyVelocity(axis, x));
  }
  fixedFace[f] = held;
  value[f] = prescribed;
  if (openPerFace) open[f] = fraction;
#else  // MODE_FLUX: VelocityConstraints::computeSolidFlux
  precise double flux = 0.0lf;
  bool fluid = false;  // (a cell closed on every side: no flux)
  for (int a = 0; a < DIM; ++a)
    for (int side = 0; side < 2; ++side) {
      ivec3 fk = k, fd = cells;
      fk[a] += side;
      fd[a] += 1;
      fluid = fluid || open[velOff[a] + indexOf(fk, fd)] > 0.0;
    }
  for (int a = 0; a < DIM && fluid; ++a)
    for (int side = 0; side < 2; ++side) {
      ivec3 fk = k, fd = cells;
      fk[a] += side;
      fd[a] += 1;
      const double closed = 1.0lf - double(open[velOff[a] + indexOf(fk, fd)]);
      if (closed > 0.0lf) {
        double x[3];
        facePosition(a, fk, x);
        flux = flux + (side != 0 ? closed : -closed) * bodyVelocity(a, x);
      }
    }
  solidFlux[indexOf(k, cells)] = flux;
#endif
}
