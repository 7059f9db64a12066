// Distance from every map cell to the nearest obstacle, capped.
//
// The likelihood field of Thrun, Burgard & Fox, "Probabilistic Robotics"
// (2005), ch. 6.4, scores a beam by how far its end point lands from the
// nearest occupied cell. The distances are computed once per map with an
// exact linear-time Euclidean distance transform.
//
// Unknown cells are not obstacles: their distance is measured to the nearest
// occupied cell like any other. Points outside the map are max_distance away,
// so a beam that leaves the map scores like one in open space.
// The surface distance differs inside obstacles: how far past the surface a
// point lies, less kFreeDepth cells, so that for the scan fit (bicubic
// distance field) a thick wall is not a better fit the deeper a beam goes.
//
// Both come from one 16-bit class a cell (a 200 x 600 m floor at 5 cm has 48
// million cells): the distances take few values (square roots of sums of two
// squares of whole cells, up to the cap, and the same inside obstacles), so a
// cell holds the index of its value among them, and the values are tables of
// a few thousand floats. The likelihood field scores a beam by its end cell's
// class through a table of its own (likelihood_field_model.h). The exact
// values take at most kMaxClasses classes; a cap of more than about 550
// cells would need more, and then neighbouring values share a class.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf {

class DistanceField {
 public:
  /// Cells behind an obstacle's surface cell that still count as on it (a
  /// real map's walls are blurred over two or three cells).
  static constexpr float kFreeDepth = 1.0f;

  /// Classes at most (a class is 16 bits).
  static constexpr std::size_t kMaxClasses = 65535;
  /// The cap at most, in cells: the distinct values are listed up to it.
  static constexpr double kMaxCapCells = 2048.0;

  /// Throws std::invalid_argument when max_distance is not positive and
  /// finite, or more than kMaxCapCells cells, or when the map is more than
  /// kMaxRowPassCells (distance_transform.h) wide. Keeps `grid` (moved in: a
  /// large map is not held twice). Its passes run on up to `threads`
  /// threads (WorkerPool); the result is the same on any number.
  DistanceField(OccupancyGrid grid, double max_distance, int threads = 1);

  double maxDistance() const { return max_distance_; }
  const OccupancyGrid& grid() const { return grid_; }

  /// Distance in metres to the nearest occupied cell centre, at most max_distance.
  double distance(const CellIndex& c) const {
    return grid_.contains(c) ? distance(static_cast<std::size_t>(grid_.linearIndex(c)))
                             : max_distance_;
  }
  double distanceAt(double wx, double wy) const { return distance(grid_.worldToCell(wx, wy)); }

  /// Cell i's (row-major) distance: metres to the nearest occupied cell
  /// centre, at most max_distance; +0.0f on an occupied cell.
  float distance(std::size_t i) const { return distances_[classes_[i]]; }
  /// Cell i's surface distance: its distance, but inside an obstacle how far
  /// past its surface (less kFreeDepth cells, at most max_distance; +0.0f
  /// near the surface): what the scan fit measures. See docs/design.md, "A
  /// map out of date is not a wrong pose".
  float surfaceDistance(std::size_t i) const { return surfaces_[classes_[i]]; }
  std::size_t size() const { return classes_.size() - 1; }
  /// Every cell's surface distance as a float, row-major, on a map of up to
  /// kMaxFloatCells cells (nullptr on a larger one): the scan fit's
  /// stencils read four neighbours in one load there, where classes take a
  /// gather and a lookup each (the refinement's samples cost twice as much).
  const float* surfaceCells() const {
    return surface_cells_.empty() ? nullptr : surface_cells_.data();
  }
  static constexpr std::size_t kMaxFloatCells = std::size_t{16} << 20;

  /// Every cell's class, row-major, for loops over many cells: the cell's
  /// distance is classDistances()[class], its surface distance
  /// classSurfaceDistances()[class]. One more entry follows the last cell,
  /// so that a four-byte read at any cell stays inside.
  const uint16_t* classes() const { return classes_.data(); }
  /// Classes are numbered in increasing order of their values, so their
  /// distances never decrease: a cell lies within `d` metres of an
  /// obstacle exactly when its class is below classesWithin(d).
  const std::vector<float>& classDistances() const { return distances_; }
  std::size_t classesWithin(double d) const {
    return static_cast<std::size_t>(std::upper_bound(distances_.begin(), distances_.end(), d,
                                                     [](double v, float c) { return v < c; }) -
                                    distances_.begin());
  }
  const std::vector<float>& classSurfaceDistances() const { return surfaces_; }

 private:
  struct ValueClasses;
  static bool occupied(int8_t value) {
    return OccupancyGrid::classify(value) == CellState::kOccupied;
  }
  // The distances to the obstacles, into classes_.
  void transformOutside(const ValueClasses& values, int threads);
  // The depths of the occupied cells, into their classes_.
  void transformInside(const ValueClasses& values, int threads);

  OccupancyGrid grid_;
  double max_distance_;
  std::vector<uint16_t> classes_;  // see classes()
  std::vector<float> distances_, surfaces_;
  std::vector<float> surface_cells_;  // see surfaceCells()
};

}  // namespace pf
