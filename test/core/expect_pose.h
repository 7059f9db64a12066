// Test helper shared by the core's tests: two planar poses agree within a
// tolerance, yaw compared as an angle (so pi and -pi agree).
#pragma once

#include <gtest/gtest.h>

#include "pf_localization/core/util/pose2.h"

namespace pf {

inline void expectPoseNear(const Pose2& expected, const Pose2& actual, double tol, double yaw_tol) {
  EXPECT_NEAR(expected.x, actual.x, tol);
  EXPECT_NEAR(expected.y, actual.y, tol);
  EXPECT_NEAR(0.0, angleDiff(expected.yaw, actual.yaw), yaw_tol)
      << "yaw " << actual.yaw << ", expected " << expected.yaw;
}

inline void expectPoseNear(const Pose2& expected, const Pose2& actual, double tol = 1e-12) {
  expectPoseNear(expected, actual, tol, tol);
}

}  // namespace pf
