#include "pf_localization/ros/output/republish_schedule.h"

#include <gtest/gtest.h>

namespace pf_ros {
namespace {

const ros::Duration kPeriod(0.05);  // 20 Hz

TEST(RepublishSchedule, DueAtOnceThenOnePeriodAfterTheLatestPublication) {
  RepublishSchedule schedule;
  EXPECT_TRUE(schedule.due(ros::Time(10.0), kPeriod));
  schedule.published(ros::Time(10.0), kPeriod);
  EXPECT_FALSE(schedule.due(ros::Time(10.049), kPeriod));
  EXPECT_TRUE(schedule.due(ros::Time(10.05), kPeriod));
  EXPECT_EQ(ros::Time(10.05), schedule.next());
}

TEST(RepublishSchedule, AnUpdatesPublicationPutsTheNextTimedOneOff) {
  // A timed publication at 10.00 and an update's at 10.03: nothing more is
  // needed before 10.08 (on a fixed beat, 10.05 would have sent another).
  RepublishSchedule schedule;
  ASSERT_TRUE(schedule.due(ros::Time(10.0), kPeriod));
  schedule.published(ros::Time(10.0), kPeriod);
  schedule.published(ros::Time(10.03), kPeriod);
  EXPECT_FALSE(schedule.due(ros::Time(10.05), kPeriod));
  EXPECT_FALSE(schedule.due(ros::Time(10.079), kPeriod));
  EXPECT_TRUE(schedule.due(ros::Time(10.08), kPeriod));
}

TEST(RepublishSchedule, TimeGoingBackOrAResetMakesItDueAtOnce) {
  RepublishSchedule schedule;
  schedule.published(ros::Time(100.0), kPeriod);
  // A bag that starts over: its clock is far behind the schedule.
  EXPECT_TRUE(schedule.due(ros::Time(5.0), kPeriod));
  schedule.published(ros::Time(5.0), kPeriod);
  EXPECT_FALSE(schedule.due(ros::Time(5.01), kPeriod));
  schedule.reset();
  EXPECT_TRUE(schedule.due(ros::Time(5.01), kPeriod));
}

}  // namespace
}  // namespace pf_ros
