#include "pf_localization/core/estimate/scan_refiner.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/expect_pose.h"
#include "support/grid_from_rows.h"

namespace pf {
namespace {

// The worlds below are drawn in 0.1 m cells, origin at the lower-left corner.
constexpr double kCell = 0.1;

// 1.6 m x 1.2 m: walls, a square block and a stub, so that every direction
// of the pose is pinned down.
const std::vector<std::string> kRoom = {
    "################",  //
    "#..............#",  //
    "#..............#",  //
    "#....##........#",  //
    "#....##........#",  //
    "#..............#",  //
    "#..............#",  //
    "#.........#....#",  //
    "#.........#....#",  //
    "#..............#",  //
    "#..............#",  //
    "################",  //
};

// End points on the centres of the given grid's occupied cells, seen from
// `pose`: at `pose` every one lies exactly on an obstacle.
PreparedScan scanOfObstacles(const OccupancyGrid& grid, const Pose2& pose, int margin = 0) {
  PreparedScan scan;
  scan.range_max = 10.0;
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = margin; x < grid.width() - margin; ++x) {
      if (grid.state({x, y}) != CellState::kOccupied) continue;
      double wx, wy;
      grid.cellToWorld({x, y}, &wx, &wy);
      const Pose2 local = between(pose, {wx, wy, 0.0});
      scan.x.push_back(static_cast<float>(local.x));
      scan.y.push_back(static_cast<float>(local.y));
    }
  }
  return scan;
}

const Pose2 kTruth{0.83, 0.57, 0.2};

TEST(ScanRefiner, RecoversAKnownOffsetToAMillimetre) {
  const OccupancyGrid grid = test::gridFromRows(kRoom, kCell);
  const DistanceField field(grid, 2.0);
  const ScanRefiner refiner(field, ScanRefinerParams());
  const PreparedScan scan = scanOfObstacles(grid, kTruth);
  ASSERT_EQ(58u, scan.size());
  const Pose2 start{kTruth.x + 0.06, kTruth.y - 0.04, kTruth.yaw + 0.05};
  const ScanRefinement r = refiner.refine(scan, start);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  EXPECT_EQ(ScanRejection::kNone, r.rejection);
  EXPECT_EQ("", r.rejection_detail);
  expectPoseNear(kTruth, r.pose, 1e-3, 1e-3);
  EXPECT_EQ(58, r.matched_beams);
  EXPECT_LT(r.rms_distance, 1e-3);
  EXPECT_NEAR(std::hypot(0.06, 0.04), r.translation, 1e-3);
  EXPECT_NEAR(-0.05, r.rotation, 1e-3);
  EXPECT_GE(r.iterations, 1);
  // Residuals near zero: the covariance is the floor, min_beam_std^2 H^-1,
  // and the map's walls' offsets; positive definite, and tighter than a
  // 0.1 m cell's 0.029 m std dev, as more than one wall pins every direction.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(r.covariance);
  EXPECT_GT(eig.eigenvalues()(0), 0.0);
  EXPECT_LT(std::sqrt(r.covariance(0, 0)), 0.025);
  EXPECT_LT(std::sqrt(r.covariance(1, 1)), 0.025);
  EXPECT_LT(std::sqrt(r.covariance(2, 2)), 0.025);  // rad
}

TEST(ScanRefiner, StartingAtTheTruthStaysThere) {
  const OccupancyGrid grid = test::gridFromRows(kRoom, kCell);
  const DistanceField field(grid, 2.0);
  const ScanRefiner refiner(field, ScanRefinerParams());
  const ScanRefinement r = refiner.refine(scanOfObstacles(grid, kTruth), kTruth);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  expectPoseNear(kTruth, r.pose, 1e-6, 1e-6);
}

TEST(ScanRefiner, AScanWithNothingToMatchIsRejected) {
  // A 2 m x 2 m room with nothing in it but its walls.
  std::vector<int8_t> data(400, 0);
  for (int i = 0; i < 20; ++i) data[i] = data[380 + i] = data[20 * i] = data[20 * i + 19] = 100;
  const DistanceField field(OccupancyGrid(20, 20, 0.1, {}, data), 2.0);
  const ScanRefiner refiner(field, ScanRefinerParams());
  // Twelve end points 0.1 m around the robot in the middle of the room,
  // 0.75 m or more from the walls.
  PreparedScan scan;
  for (int i = 0; i < 12; ++i) {
    scan.x.push_back(static_cast<float>(0.1 * std::cos(i * M_PI / 6)));
    scan.y.push_back(static_cast<float>(0.1 * std::sin(i * M_PI / 6)));
  }
  const Pose2 start{1.0, 1.0, 0.3};
  const ScanRefinement r = refiner.refine(scan, start);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(ScanRejection::kTooFewMatchedBeams, r.rejection);
  // The detail gives the figures.
  EXPECT_EQ("only 0 of 12 beams end within 0.3 m of a mapped obstacle (8 needed): nothing to match",
            r.rejection_detail);
  EXPECT_EQ(0, r.matched_beams);
  expectPoseNear(start, r.pose, 0.0);
  EXPECT_EQ(Eigen::Matrix3d::Zero(), r.covariance);
}

TEST(ScanRefiner, AnEmptyScanIsRejected) {
  const OccupancyGrid grid = test::gridFromRows(kRoom, kCell);
  const DistanceField field(grid, 2.0);
  const ScanRefinement r = ScanRefiner(field, ScanRefinerParams()).refine(PreparedScan(), kTruth);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(ScanRejection::kTooFewMatchedBeams, r.rejection) << r.rejection_detail;
}

TEST(ScanRefiner, AFitThatMovesTooFarIsRejected) {
  const OccupancyGrid grid = test::gridFromRows(kRoom, kCell);
  const DistanceField field(grid, 2.0);
  const PreparedScan scan = scanOfObstacles(grid, kTruth);
  const Pose2 start{kTruth.x + 0.06, kTruth.y - 0.04, kTruth.yaw};
  ScanRefinerParams params;
  params.max_translation = 0.05;  // the fit moves 0.072 m
  ScanRefinement r = ScanRefiner(field, params).refine(scan, start);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(ScanRejection::kMovedTooFar, r.rejection) << r.rejection_detail;
  expectPoseNear(start, r.pose, 0.0);
  EXPECT_NEAR(0.0721, r.translation, 1e-3);

  params = ScanRefinerParams();
  params.max_rotation = 0.02;  // the fit turns 0.05 rad
  r = ScanRefiner(field, params).refine(scan, {kTruth.x, kTruth.y, kTruth.yaw + 0.05});
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(ScanRejection::kMovedTooFar, r.rejection) << r.rejection_detail;
  EXPECT_NEAR(0.05, std::fabs(r.rotation), 1e-3);
}

// Two walls 0.8 m apart, open at both ends.
OccupancyGrid corridorGrid() {
  return test::gridFromRows(
      {
          "##############################",  //
          "..............................",  //
          "..............................",  //
          "..............................",  //
          "..............................",  //
          "..............................",  //
          "..............................",  //
          "..............................",  //
          "##############################",  //
      },
      kCell);
}

TEST(ScanRefiner, AlongAFeaturelessCorridorTheStartIsKept) {
  // The scan says nothing about x.
  const OccupancyGrid grid = corridorGrid();
  const DistanceField field(grid, 2.0);
  const Pose2 truth{1.5, 0.42, 0.0};
  // Only cells well inside the map, so that no stencil sees past its ends.
  const PreparedScan scan = scanOfObstacles(grid, truth, 6);
  const Pose2 start{truth.x + 0.07, truth.y + 0.03, 0.04};
  const ScanRefinement r = ScanRefiner(field, ScanRefinerParams()).refine(scan, start);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  EXPECT_NEAR(start.x, r.pose.x, 1e-9);  // unconstrained: kept
  EXPECT_NEAR(truth.y, r.pose.y, 1e-3);
  EXPECT_NEAR(truth.yaw, r.pose.yaw, 1e-3);
  // ... and the fit's covariance claims nothing about it.
  EXPECT_NEAR(0.0, r.covariance(0, 0), 1e-12);
  EXPECT_GT(r.covariance(1, 1), 0.0);
}

// corridorGrid() seen from `truth`, with `per_cell` end points on every cell
// of its walls' middle.
PreparedScan corridorScan(const OccupancyGrid& grid, const Pose2& truth, int per_cell) {
  const PreparedScan cells = scanOfObstacles(grid, truth, 6);
  PreparedScan scan;
  scan.range_max = cells.range_max;
  for (std::size_t b = 0; b < cells.size(); ++b) {
    for (int k = 0; k < per_cell; ++k) {
      // Spread along the wall within the cell, in scan order.
      const double along = kCell * ((k + 0.5) / per_cell - 0.5);
      scan.x.push_back(static_cast<float>(cells.x[b] + along * std::cos(truth.yaw)));
      scan.y.push_back(static_cast<float>(cells.y[b] - along * std::sin(truth.yaw)));
    }
  }
  return scan;
}

TEST(ScanRefiner, MoreBeamsOfTheSameWallsDoNotNarrowTheCovarianceBelowTheMapsError) {
  const OccupancyGrid grid = corridorGrid();
  const DistanceField field(grid, 2.0);
  const ScanRefiner refiner(field, ScanRefinerParams());
  const Pose2 truth{1.5, 0.42, 0.0};
  // Each wall is drawn with one offset, uniform over a cell: across the
  // corridor the pose is the mean of two such offsets, std dev
  // cell / sqrt(12) / sqrt(2) = 0.0204 m, however many beams end on them.
  const double walls_std = kCell / std::sqrt(12.0) / std::sqrt(2.0);
  for (const int per_cell : {1, 4, 16}) {
    const ScanRefinement r = refiner.refine(corridorScan(grid, truth, per_cell), truth);
    ASSERT_TRUE(r.accepted) << r.rejection_detail;
    const double std_y = std::sqrt(r.covariance(1, 1));
    // Above it by the residual part alone (min_beam_std, 1.5 mm here).
    EXPECT_GE(std_y, walls_std) << per_cell << " beams per cell";
    EXPECT_LT(std_y, 1.05 * walls_std) << per_cell << " beams per cell";
    // Shifting a whole wall turns nothing.
    EXPECT_LT(std::sqrt(r.covariance(2, 2)), 0.01) << per_cell << " beams per cell";
  }
}

TEST(ScanRefiner, AtACornerEachWallHasItsOwnOffset) {
  // A wall along the bottom pins y, one along the left pins x: each axis
  // rests on one wall's offset, std dev cell / sqrt(12) = 0.029 m, where
  // taking the two walls' beams as one wall, or every beam as its own,
  // would say otherwise.
  const OccupancyGrid grid = test::gridFromRows(
      {
          "#...............",  //
          "#...............",  //
          "#...............",  //
          "#...............",  //
          "#...............",  //
          "#...............",  //
          "#...............",  //
          "#...............",  //
          "################",  //
      },
      kCell);
  const DistanceField field(grid, 2.0);
  const Pose2 truth{0.62, 0.47, 0.0};
  const ScanRefinement r =
      ScanRefiner(field, ScanRefinerParams()).refine(scanOfObstacles(grid, truth), truth);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  const double wall_std = kCell / std::sqrt(12.0);
  EXPECT_GT(std::sqrt(r.covariance(0, 0)), 0.9 * wall_std);
  EXPECT_LT(std::sqrt(r.covariance(0, 0)), 1.2 * wall_std);
  EXPECT_GT(std::sqrt(r.covariance(1, 1)), 0.9 * wall_std);
  EXPECT_LT(std::sqrt(r.covariance(1, 1)), 1.2 * wall_std);
  // Two offsets drawn apart: x and y do not err together.
  EXPECT_LT(std::fabs(r.covariance(0, 1)), 0.2 * wall_std * wall_std);
}

TEST(ScanRefiner, InvalidParametersAreNamed) {
  const auto what = [](void (*change)(ScanRefinerParams&)) {
    ScanRefinerParams p;
    change(p);
    try {
      validate(p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ("invalid parameter refine_max_translation = -1: must be >= 0",
            what([](ScanRefinerParams& p) { p.max_translation = -1.0; }));
  EXPECT_EQ("invalid parameter refine_min_matched_beams = 2: must be >= 3",
            what([](ScanRefinerParams& p) { p.min_matched_beams = 2; }));
  EXPECT_EQ("invalid parameter refine_wall_offset = 0.3: must be in [0, refine_outlier_distance)",
            what([](ScanRefinerParams& p) { p.wall_offset = 0.3; }));
  EXPECT_EQ("", what([](ScanRefinerParams&) {}));
}

TEST(FusedCovariance, AddsTheInformationOfTwoEstimates) {
  const Eigen::Matrix3d a = Eigen::Vector3d(0.04, 0.01, 0.02).asDiagonal();
  const Eigen::Matrix3d b = Eigen::Vector3d(0.04, 0.03, 0.02).asDiagonal();
  const Eigen::Matrix3d f = fusedCovariance(a, b);
  // 1 / (1/a + 1/b) along each axis.
  EXPECT_NEAR(0.02, f(0, 0), 1e-9);
  EXPECT_NEAR(0.0075, f(1, 1), 1e-9);
  EXPECT_NEAR(0.01, f(2, 2), 1e-9);
}

TEST(FusedCovariance, WhatTheFitLeavesOpenKeepsThePriorsVariance) {
  // A corridor along x: the fit pins y and yaw and says nothing along x.
  const Eigen::Matrix3d fit = Eigen::Vector3d(0.0, 1e-4, 1e-5).asDiagonal();
  const Eigen::Matrix3d prior = Eigen::Vector3d(0.09, 0.01, 0.004).asDiagonal();
  const Eigen::Matrix3d f = fusedCovariance(fit, prior);
  EXPECT_NEAR(0.09, f(0, 0), 1e-9);
  EXPECT_LT(f(1, 1), 1e-4);
  EXPECT_LT(f(2, 2), 1e-5);
  // A fit that says nothing at all leaves the prior.
  EXPECT_TRUE(fusedCovariance(Eigen::Matrix3d::Zero(), prior).isApprox(prior, 1e-9));
}

TEST(CoveringCovariance, TakesTheWiderAlongEachAxis) {
  const Eigen::Matrix3d a = Eigen::Vector3d(1.0, 4.0, 0.01).asDiagonal();
  const Eigen::Matrix3d b = Eigen::Vector3d(4.0, 1.0, 0.04).asDiagonal();
  const Eigen::Matrix3d c = coveringCovariance(a, b);
  EXPECT_TRUE(c.isApprox(Eigen::Vector3d(4.0, 4.0, 0.04).asDiagonal().toDenseMatrix(), 1e-9)) << c;
}

TEST(CoveringCovariance, TheWiderOfTwoNestedIsKept) {
  Eigen::Matrix3d wide;
  wide << 0.04, 0.01, 0.0,  //
      0.01, 0.03, 0.002,    //
      0.0, 0.002, 0.01;
  const Eigen::Matrix3d narrow = 0.01 * wide;
  EXPECT_TRUE(coveringCovariance(narrow, wide).isApprox(wide, 1e-9));
  EXPECT_TRUE(coveringCovariance(wide, narrow).isApprox(wide, 1e-9));
  // A zero covariance (the fit says nothing) leaves the other.
  EXPECT_TRUE(coveringCovariance(Eigen::Matrix3d::Zero(), wide).isApprox(wide, 1e-9));
}

TEST(CoveringCovariance, CoversBothWhenTheyCross) {
  Eigen::Matrix3d a;
  a << 2.0, 1.0, 0.0,  //
      1.0, 2.0, 0.0,   //
      0.0, 0.0, 0.1;
  const Eigen::Matrix3d b = Eigen::Vector3d(3.0, 0.5, 0.2).asDiagonal();
  const Eigen::Matrix3d c = coveringCovariance(a, b);
  for (const Eigen::Matrix3d& d : {Eigen::Matrix3d(c - a), Eigen::Matrix3d(c - b)}) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(d);
    EXPECT_GE(eig.eigenvalues()(0), -1e-9) << d;
  }
}

}  // namespace
}  // namespace pf
