// Which updates pf_node runs on roscpp's poll thread: only those that the
// recent updates, scaled to the particle count, show to be short.
#include "pf_localization/ros/scheduling/update_placement.h"

#include <gtest/gtest.h>

namespace pf_ros {
namespace {

constexpr double kBudget = UpdatePlacement::kBudget;

void addShort(UpdatePlacement* p, std::size_t n, std::size_t particles) {
  for (std::size_t i = 0; i < n; ++i) p->addUpdate(0.2 * kBudget, particles);
}

TEST(UpdatePlacement, HandsOverUntilAWholeWindowOfUpdatesWasShort) {
  UpdatePlacement p;
  EXPECT_FALSE(p.onPollThread(10));
  addShort(&p, UpdatePlacement::kWindow - 1, 10);
  EXPECT_FALSE(p.onPollThread(10));
  addShort(&p, 1, 10);
  EXPECT_TRUE(p.onPollThread(10));
}

TEST(UpdatePlacement, OneLongUpdateHandsOverUntilItLeavesTheWindow) {
  UpdatePlacement p;
  addShort(&p, UpdatePlacement::kWindow, 5000);
  p.addUpdate(1.5 * kBudget, 5000);
  for (std::size_t i = 0; i < UpdatePlacement::kWindow; ++i) {
    EXPECT_FALSE(p.onPollThread(5000)) << i;
    p.addUpdate(0.2 * kBudget, 5000);
  }
  EXPECT_TRUE(p.onPollThread(5000));
}

TEST(UpdatePlacement, ACloudThatGrewIsHandedOverByItsScaledCost) {
  UpdatePlacement p;
  addShort(&p, UpdatePlacement::kWindow, 5000);  // 0.2 budgets each
  EXPECT_TRUE(p.onPollThread(5000));
  EXPECT_TRUE(p.onPollThread(24000));   // 4.8 times: within the budget
  EXPECT_FALSE(p.onPollThread(26000));  // more than five times
  EXPECT_FALSE(p.onPollThread(50000));  // global localization's cloud
  EXPECT_TRUE(p.onPollThread(100));     // fewer particles are not scaled down
}

TEST(UpdatePlacement, ResetForgetsTheCostsSeen) {
  UpdatePlacement p;
  addShort(&p, UpdatePlacement::kWindow, 10);
  p.reset();
  EXPECT_FALSE(p.onPollThread(10));
  addShort(&p, UpdatePlacement::kWindow, 10);
  EXPECT_TRUE(p.onPollThread(10));
}

}  // namespace
}  // namespace pf_ros
