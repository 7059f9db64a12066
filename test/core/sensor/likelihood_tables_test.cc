#include "pf_localization/core/sensor/likelihood_tables.h"

#include <gtest/gtest.h>

#include <vector>

namespace pf {
namespace {

// A "table" that says which range_max it was built for.
void fill(double range_max, std::vector<float>* table) {
  table->assign(3, static_cast<float>(range_max));
}

TEST(LikelihoodTables, TwoSensorsRangesAreEachBuiltOnce) {
  // A front lidar of 25 m and a rear one of 12 m, both in every update.
  LikelihoodTables tables;
  for (int update = 0; update < 10; ++update) {
    EXPECT_EQ(25.0f, tables.get(25.0, fill)[0]);
    EXPECT_EQ(12.0f, tables.get(12.0, fill)[0]);
  }
  EXPECT_EQ(2u, tables.builds());
}

TEST(LikelihoodTables, PastTheLimitTheOneUsedLongestAgoIsRebuilt) {
  LikelihoodTables tables;
  for (std::size_t i = 0; i < LikelihoodTables::kMaxTables; ++i) tables.get(10.0 + i, fill);
  tables.get(10.0, fill);  // 11 is now the one used longest ago
  EXPECT_EQ(LikelihoodTables::kMaxTables, tables.builds());
  EXPECT_EQ(99.0f, tables.get(99.0, fill)[0]);
  EXPECT_EQ(LikelihoodTables::kMaxTables + 1, tables.builds());
  EXPECT_EQ(10.0f, tables.get(10.0, fill)[0]);  // kept
  EXPECT_EQ(12.0f, tables.get(12.0, fill)[0]);  // kept
  EXPECT_EQ(LikelihoodTables::kMaxTables + 1, tables.builds());
  EXPECT_EQ(11.0f, tables.get(11.0, fill)[0]);  // evicted: built again
  EXPECT_EQ(LikelihoodTables::kMaxTables + 2, tables.builds());
}

}  // namespace
}  // namespace pf
