#include "fluid/obstacle_motion.h"

#include <algorithm>
#include <cmath>

#include "core/expression.h"
#include "fluid/obstacle_shape.h"

namespace morphoflow {

namespace {

using Matrix = std::array<double, 9>;  // row-major

Matrix multiply(const Matrix& a, const Matrix& b) {
  Matrix c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[size_t(3 * i + j)] += a[size_t(3 * i + k)] * b[size_t(3 * k + j)];
  return c;
}
// The rotation by `angle` about axis 0, 1 or 2.
Matrix about(int axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const int p = (axis + 1) % 3, q = (axis + 2) % 3;
  Matrix m{};
  m[size_t(4 * axis)] = 1.0;
  m[size_t(3 * p + p)] = c, m[size_t(3 * p + q)] = -s;
  m[size_t(3 * q + p)] = s, m[size_t(3 * q + q)] = c;
  return m;
}
std::array<double, 3> column(const Matrix& m, int j) { return {m[size_t(j)], m[size_t(3 + j)], m[size_t(6 + j)]}; }

// An expression in t and its derivative there.
void evaluate(const std::string& text, double t, double* value, double* rate, bool* analytic) {
  const Expression e(text, {"t"});
  *value = e.evaluate(&t);
  bool exact = true;
  *rate = e.derivative(&t, 0, &exact);
  if (analytic && !exact) *analytic = false;
}

}  // namespace

std::array<double, 3> RigidMotion::at(const double* x, int dims) const {
  return {at(x, dims, 0), at(x, dims, 1), at(x, dims, 2)};
}

double RigidMotion::at(const double* x, int dims, int axis) const {
  return obstacle_shape::osRigidVelocity(axis, dims, x, center.data(), velocity.data(), omega.data());
}

bool anyMoves(const std::vector<ObstacleSpec>& obstacles) {
  return std::any_of(obstacles.begin(), obstacles.end(), [](const ObstacleSpec& o) { return movesAtAll(o); });
}

ObstacleSpec placedAt(const ObstacleSpec& o, int dims, double t, RigidMotion* motion, bool* analytic) {
  ObstacleSpec p = o;
  RigidMotion m;
  for (size_t a = 0; a < o.motion.size(); ++a) evaluate(o.motion[a], t, &p.center[a], &m.velocity[a], analytic);
  m.center = p.center;
  if (!o.rotation.empty()) {
    // 2D: one angle about z; 3D: about x, y, z, R = Rz Ry Rx.
    std::array<double, 3> angle{0, 0, 0}, rate{0, 0, 0};
    const size_t first = dims == 2 ? 2 : 0;
    for (size_t k = 0; k < o.rotation.size(); ++k)
      evaluate(o.rotation[k], t, &angle[first + k], &rate[first + k], analytic);
    const Matrix rz = about(2, angle[2]), rzy = multiply(rz, about(1, angle[1]));
    p.orientation = multiply(rzy, about(0, angle[0]));
    const std::array<double, 3> ey = column(rz, 1), ex = column(rzy, 0);
    for (size_t a = 0; a < 3; ++a) m.omega[a] = rate[1] * ey[a] + rate[0] * ex[a] + (a == 2 ? rate[2] : 0.0);
  }
  if (motion) *motion = m;
  return p;
}

std::vector<ObstacleSpec> placedAt(const std::vector<ObstacleSpec>& obstacles, int dims, double t,
                                   std::vector<RigidMotion>* motions) {
  std::vector<ObstacleSpec> out;
  motions->assign(obstacles.size(), RigidMotion{});
  for (size_t i = 0; i < obstacles.size(); ++i) out.push_back(placedAt(obstacles[i], dims, t, &(*motions)[i]));
  return out;
}

bool obstacleBounds(const ObstacleSpec& o, int dims, const double* size, double* lo, double* hi) {
  double reach = o.radius;
  if (o.shape == ObstacleShape::Image || o.shape == ObstacleShape::Sdf) return false;
  if (o.shape == ObstacleShape::Circle && dims == 3) return false;
  if (o.shape == ObstacleShape::Box) {
    double d2 = 0.0;
    for (int a = 0; a < dims; ++a) d2 += o.halfSize[size_t(a)] * o.halfSize[size_t(a)];
    reach = std::sqrt(d2);
  }
  for (int a = 0; a < dims; ++a) {
    double c = o.center[size_t(a)];
    if (o.wrap[size_t(a)]) c -= size[a] * std::floor(c / size[a]);
    lo[a] = c - reach;
    hi[a] = c + reach;
  }
  return true;
}

double obstacleSpeedBound(const ObstacleSpec& o, int dims, double t) {
  if (!movesAtAll(o)) return 0.0;
  RigidMotion m;
  placedAt(o, dims, t, &m);
  double reach = o.radius;
  if (o.shape == ObstacleShape::Box) {
    double d2 = 0.0;
    for (int a = 0; a < dims; ++a) d2 += o.halfSize[size_t(a)] * o.halfSize[size_t(a)];
    reach = std::sqrt(d2);
  }
  auto norm = [](const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  return norm(m.velocity) + norm(m.omega) * reach;
}

}  // namespace morphoflow
