// A rigid-body pose in the plane and the few operations the filter needs on it.
//
// Poses compose as SE(2) transforms: compose(a, b) is "b expressed in the frame
// whose pose is a". Angles are radians, always kept in (-pi, pi].
#pragma once

#include <cmath>

namespace pf {

/// Wraps an angle into (-pi, pi]; safe for any finite input.
inline double normalizeAngle(double a) {
  // Nearly every angle here is a sum of two wrapped ones: a single step of
  // 2 pi wraps it, far cheaper than the general remainder.
  if (a > M_PI) {
    a -= 2.0 * M_PI;
  } else if (a <= -M_PI) {
    a += 2.0 * M_PI;
  }
  if (a > M_PI || a <= -M_PI) {
    a = std::remainder(a, 2.0 * M_PI);  // in [-pi, pi]
    if (a <= -M_PI) a += 2.0 * M_PI;
  }
  return a;
}

/// Smallest signed difference a - b, in (-pi, pi].
inline double angleDiff(double a, double b) { return normalizeAngle(a - b); }

struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;

  bool isFinite() const { return std::isfinite(x) && std::isfinite(y) && std::isfinite(yaw); }
  bool isIdentity() const { return x == 0.0 && y == 0.0 && yaw == 0.0; }
};

/// a (+) b: the pose b, given in frame a, expressed in a's parent frame.
inline Pose2 compose(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.yaw), s = std::sin(a.yaw);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, normalizeAngle(a.yaw + b.yaw)};
}

/// The inverse transform: compose(a, inverse(a)) is the identity.
inline Pose2 inverse(const Pose2& a) {
  const double c = std::cos(a.yaw), s = std::sin(a.yaw);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, normalizeAngle(-a.yaw)};
}

/// a^-1 (+) b: the pose b seen from a.
inline Pose2 between(const Pose2& a, const Pose2& b) { return compose(inverse(a), b); }

}  // namespace pf
