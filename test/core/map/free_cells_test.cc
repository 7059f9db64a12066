#include "pf_localization/core/map/free_cells.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace pf {
namespace {

TEST(FreeCells, NoneFree) {
  const FreeCells none(100, [](std::size_t) { return false; });
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(0u, none.size());
  EXPECT_TRUE(FreeCells().empty());
}

TEST(FreeCells, TheKthFreeCellAsAListOfThemHasIt) {
  // Words all free, none free and mixed, and a last word cut short.
  std::mt19937 rng(7);
  const std::size_t cells = 64 * 40 + 17;
  std::vector<bool> free(cells);
  std::vector<int> list;
  for (std::size_t i = 0; i < cells; ++i) {
    const std::size_t word = i / 64;
    free[i] = word % 4 == 0 ? true : word % 4 == 1 ? false : rng() % 3 == 0;
    if (free[i]) list.push_back(static_cast<int>(i));
  }
  const FreeCells set(cells, [&free](std::size_t i) { return free[i]; });
  ASSERT_EQ(list.size(), set.size());
  for (std::size_t k = 0; k < list.size(); ++k) ASSERT_EQ(list[k], set[k]) << "k = " << k;
}

TEST(FreeCells, AFewBitsACell) {
  // What it is for: 48 million cells (200 x 600 m at 0.05 m) in 9 MB, where
  // a list of the free ones' indices took 190 MB.
  const std::size_t cells = 48'000'000;
  const FreeCells all(cells, [](std::size_t i) { return i % 5 != 0; });
  EXPECT_EQ(cells / 5 * 4, all.size());
  EXPECT_EQ(1, all[0]);
  EXPECT_EQ(47'999'999, all[all.size() - 1]);
  EXPECT_LE(all.bytes(), cells / 64 * 12 + 12);
}

}  // namespace
}  // namespace pf
