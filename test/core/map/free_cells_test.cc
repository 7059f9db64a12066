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

TEST(FreeCells, OfValuesIsTheSetOfItsPredicate) {
  // Every value a cell can hold, in runs that end anywhere in a word.
  std::mt19937 rng(7);
  for (std::size_t cells : {0, 1, 7, 8, 63, 64, 65, 200, 1000}) {
    std::vector<int8_t> values(cells);
    for (int8_t& v : values) v = static_cast<int8_t>(rng() % 256);
    for (int8_t free_max : {0, 19, 64, 126}) {
      const FreeCells fast = FreeCells::ofValues(values.data(), cells, free_max);
      const FreeCells slow(cells,
                           [&](std::size_t i) { return values[i] >= 0 && values[i] <= free_max; });
      ASSERT_EQ(slow.size(), fast.size()) << cells << " cells, free_max " << int{free_max};
      for (std::size_t k = 0; k < slow.size(); ++k) ASSERT_EQ(slow[k], fast[k]);
    }
  }
}

}  // namespace
}  // namespace pf
