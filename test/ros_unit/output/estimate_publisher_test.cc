// What pf_node's output decides without publishing: when the particle cloud
// is due, and which changes of the localization state are logged.
#include "pf_localization/ros/output/estimate_publisher.h"

#include <gtest/gtest.h>

namespace pf_ros {
namespace {

TEST(CloudDue, AtMostAtTheGuiRateUnlessAReinitialisation) {
  const ros::Time last(10.0);
  EXPECT_TRUE(cloudDue(ros::Time(), ros::Time(10.0), 2.0, false));  // the first
  EXPECT_FALSE(cloudDue(last, ros::Time(10.4), 2.0, false));
  EXPECT_TRUE(cloudDue(last, ros::Time(10.5), 2.0, false));
  EXPECT_TRUE(cloudDue(last, ros::Time(10.1), 2.0, true));    // re-initialised
  EXPECT_TRUE(cloudDue(last, ros::Time(5.0), 2.0, false));    // time went back
  EXPECT_TRUE(cloudDue(last, ros::Time(10.01), 0.0, false));  // no limit
}

TEST(StateChangeLog, EachChangeOnceWarningUnlessLocalized) {
  StateChangeLog log;
  pf::Confidence c;
  c.state = pf::LocalizationState::kLost;
  c.reason = "few beams fit";
  const auto lost = log.onConfidence(c);
  ASSERT_TRUE(lost);
  EXPECT_TRUE(lost->warning);
  EXPECT_EQ(std::string(pf::toString(pf::LocalizationState::kLost)) + ": few beams fit",
            lost->text);
  EXPECT_FALSE(log.onConfidence(c));  // the same state: no news
  c.state = pf::LocalizationState::kLocalized;
  c.reason = "one cluster";
  const auto localized = log.onConfidence(c);
  ASSERT_TRUE(localized);
  EXPECT_FALSE(localized->warning);
  EXPECT_EQ("localized: one cluster", localized->text);
  c.state = pf::LocalizationState::kUncertain;
  ASSERT_TRUE(log.onConfidence(c));
  EXPECT_TRUE(log.onConfidence(c) == std::nullopt);
}

}  // namespace
}  // namespace pf_ros
