// ParticleFilter's initialisation: a filter starts with no map and no
// particles; initializeGaussian draws the given mean and covariance (and
// refuses a pose or covariance that is not one); initializeUniform fills the
// map's free space.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/filter/particle_filter_world.h"
#include "pf_localization/core/filter/particle_filter.h"

namespace pf {
namespace {

using filter_world::asymmetricRoom;
using filter_world::baseParams;
using filter_world::diag;

// --- Initialisation --------------------------------------------------------------

TEST(ParticleFilter, StartsUninitialisedWithoutMap) {
  ParticleFilter filter(baseParams());
  EXPECT_FALSE(filter.hasMap());
  EXPECT_EQ(nullptr, filter.map());
  EXPECT_FALSE(filter.isInitialized());
  EXPECT_FALSE(filter.mapToOdom().has_value());
  EXPECT_THROW(filter.initializeUniform(), std::logic_error);
}

TEST(ParticleFilter, InitializeGaussian) {
  ParticleFilter filter(baseParams());
  filter.initializeGaussian({1.0, 2.0, 3.0}, diag(0.2, 0.1, 0.05));
  ASSERT_TRUE(filter.isInitialized());
  const ParticleSet& p = filter.particles();
  ASSERT_EQ(2000u, p.size());  // max_particles
  double sx = 0, sy = 0, sxx = 0, syy = 0, sw = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    sx += p.x[i];
    sy += p.y[i];
    sxx += (p.x[i] - 1.0) * (p.x[i] - 1.0);
    syy += (p.y[i] - 2.0) * (p.y[i] - 2.0);
    sw += p.weight[i];
    ASSERT_GT(p.yaw[i], -M_PI);
    ASSERT_LE(p.yaw[i], M_PI);
  }
  EXPECT_NEAR(1.0, sx / p.size(), 0.02);
  EXPECT_NEAR(2.0, sy / p.size(), 0.01);
  // Standard errors: 0.2 / sqrt(2 * 2000) = 0.0032 and half that; 5 of them.
  EXPECT_NEAR(0.2, std::sqrt(sxx / p.size()), 0.016);
  EXPECT_NEAR(0.1, std::sqrt(syy / p.size()), 0.008);
  EXPECT_NEAR(1.0, sw, 1e-9);
  // yaw 3.0 +- 0.05 wraps past pi for some particles; the estimate does not care.
  EXPECT_NEAR(0.0, angleDiff(filter.estimate().pose.yaw, 3.0), 0.01);
  EXPECT_NEAR(1.0, filter.estimate().pose.x, 0.02);
  // No update yet: no map -> odom.
  EXPECT_FALSE(filter.mapToOdom().has_value());
}

TEST(ParticleFilter, InitializeGaussianCorrelatedAndSemiDefinite) {
  ParticleFilter filter(baseParams());
  // x and y perfectly correlated, yaw fixed: every particle on the line y - 2 = x - 1.
  Eigen::Matrix3d cov;
  cov << 0.04, 0.04, 0.0,  //
      0.04, 0.04, 0.0,     //
      0.0, 0.0, 0.0;
  filter.initializeGaussian({1.0, 2.0, 0.5}, cov);
  const ParticleSet& p = filter.particles();
  double spread = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(p.x[i] - 1.0, p.y[i] - 2.0, 1e-9);
    EXPECT_EQ(0.5, p.yaw[i]);
    spread = std::max(spread, std::fabs(p.x[i] - 1.0));
  }
  EXPECT_GT(spread, 0.3);  // it is not collapsed to a point either
}

TEST(ParticleFilter, InitializeGaussianReproducesAFullCovariance) {
  // Largest variance on y, then yaw, then x, and x correlated with yaw: the
  // factorisation must pivot and undo the pivoting.
  Eigen::Matrix3d cov;
  cov << 0.01, 0.0, 0.012,  //
      0.0, 0.09, 0.0,       //
      0.012, 0.0, 0.04;
  ParticleFilterParams params = baseParams();
  params.kld.min_particles = params.kld.max_particles = 20000;
  ParticleFilter filter(params);
  filter.initializeGaussian({0.0, 0.0, 0.0}, cov);
  const ParticleSet& p = filter.particles();
  Eigen::Matrix3d sample = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d d(p.x[i], p.y[i], p.yaw[i]);
    sample += d * d.transpose() / static_cast<double>(p.size());
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      // Within four standard errors of a Gaussian sample (co)variance:
      // sqrt((s_rr s_cc + s_rc^2) / n), at most 9e-4 here.
      const double se = std::sqrt((cov(r, r) * cov(c, c) + cov(r, c) * cov(r, c)) /
                                  static_cast<double>(p.size()));
      EXPECT_NEAR(cov(r, c), sample(r, c), 4.0 * se) << r << "," << c;
    }
  }
}

TEST(ParticleFilter, InitializeGaussianRejectsBadInput) {
  ParticleFilter filter(baseParams());
  EXPECT_THROW(filter.initializeGaussian({NAN, 0, 0}, diag(0.1, 0.1, 0.1)), std::invalid_argument);
  Eigen::Matrix3d asymmetric = diag(0.1, 0.1, 0.1);
  asymmetric(0, 1) = 0.01;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, asymmetric), std::invalid_argument);
  Eigen::Matrix3d negative = diag(0.1, 0.1, 0.1);
  negative(2, 2) = -0.01;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, negative), std::invalid_argument);
  Eigen::Matrix3d indefinite;   // symmetric, eigenvalues 1.5 and -0.5
  indefinite << 0.5, 1.0, 0.0,  //
      1.0, 0.5, 0.0,            //
      0.0, 0.0, 0.1;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, indefinite), std::invalid_argument);
  Eigen::Matrix3d nan = diag(0.1, 0.1, 0.1);
  nan(1, 1) = NAN;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, nan), std::invalid_argument);
  EXPECT_FALSE(filter.isInitialized());
}

TEST(ParticleFilter, InitializeUniformFillsFreeSpaceOnly) {
  ParticleFilter filter(baseParams());
  const OccupancyGrid grid = asymmetricRoom();
  EXPECT_FALSE(filter.setMap(grid));  // nothing to keep yet
  ASSERT_TRUE(filter.hasMap());
  EXPECT_EQ(grid.width(), filter.map()->width());
  filter.initializeUniform();
  const ParticleSet& p = filter.particles();
  ASSERT_EQ(2000u, p.size());
  double min_x = 1e9, max_x = -1e9, min_yaw = 1e9, max_yaw = -1e9;
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_TRUE(grid.isFreeAt(p.x[i], p.y[i])) << p.x[i] << ", " << p.y[i];
    min_x = std::min(min_x, p.x[i]);
    max_x = std::max(max_x, p.x[i]);
    min_yaw = std::min(min_yaw, p.yaw[i]);
    max_yaw = std::max(max_yaw, p.yaw[i]);
  }
  // Spread over the whole room and all headings.
  EXPECT_LT(min_x, 0.3);
  EXPECT_GT(max_x, 3.7);
  EXPECT_LT(min_yaw, -3.0);
  EXPECT_GT(max_yaw, 3.0);

  ParticleFilter walled(baseParams());
  walled.setMap(OccupancyGrid(4, 4, 0.1, {}, std::vector<int8_t>(16, 100)));
  EXPECT_THROW(walled.initializeUniform(), std::logic_error);
}

}  // namespace
}  // namespace pf
