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

TEST(RepublishSchedule, TheLastChanceBeforeTheDueTimePublishesWhenTheNextComesAfterIt) {
  // /clock in steps of 40 ms (a bag at 4x), due 50 ms after 10.00: 10.04 is
  // the last /clock before 10.05 (the next is at 10.08), so it publishes;
  // waiting for 10.08, a step of 70 ms at 10.11 would have left 0.11 s.
  RepublishSchedule schedule;
  schedule.published(ros::Time(10.0), kPeriod);
  EXPECT_TRUE(schedule.due(ros::Time(10.04), kPeriod, ros::Time(10.08)));
  // The next chance at the due time or before it: wait for it.
  EXPECT_FALSE(schedule.due(ros::Time(10.04), kPeriod, ros::Time(10.05)));
  EXPECT_FALSE(schedule.due(ros::Time(10.01), kPeriod, ros::Time(10.02)));
  // The next chance unknown (zero, the wall clock's timer): a period passed.
  EXPECT_FALSE(schedule.due(ros::Time(10.04), kPeriod));
  EXPECT_TRUE(schedule.due(ros::Time(10.05), kPeriod));
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
