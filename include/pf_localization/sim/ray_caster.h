// Simulated laser ranges: exact ray casting on the occupancy grid, then the
// imperfections of a Neato XV-11 lidar on top.
//
// Ray casting walks the cells a ray crosses in order, one cell boundary at a
// time (Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray
// Tracing", Eurographics 1987), and stops at the first occupied cell. The
// range is where the ray enters that cell, so it is exact for the grid, not
// rounded to cell centres. Unknown cells are transparent (nothing is there to
// reflect), and a ray that leaves the map returns nothing.
//
// The Neato model (neatoReadings) turns those ideal ranges into readings:
//   - nothing within range_max, or a dropout: 0.0, as the Neato reports it;
//   - dropouts come singly, with a probability growing linearly with range
//     (weak returns from far walls), and in bursts of consecutive beams
//     (dark or shiny patches): the real AC109 bag loses ~39 % of its beams,
//     mostly in runs of 1-10;
//   - a small fraction of beams hit something that is not on the map and
//     return a uniformly random shorter range;
//   - Gaussian noise, then rounding to the Neato's 1 mm resolution.
#pragma once

#include <vector>

#include "pf_localization/core/occupancy_grid.h"
#include "pf_localization/core/random.h"

namespace pf::sim {

class RayCaster {
 public:
  /// Keeps a copy of the grid.
  explicit RayCaster(const OccupancyGrid& grid) : grid_(grid) {}

  const OccupancyGrid& grid() const { return grid_; }

  /// Distance from (x, y) along the world heading `angle` to the first
  /// occupied cell: 0 when (x, y) is inside one, +inf when no occupied cell
  /// lies within max_range, or when the ray (or its origin) is off the map.
  double cast(double x, double y, double angle, double max_range) const;

 private:
  OccupancyGrid grid_;
};

/// Distance from (x, y) along `angle` to a circle of radius r at (cx, cy);
/// +inf when the ray misses it or starts inside it.
double castToCircle(double x, double y, double angle, double cx, double cy, double r);

struct NeatoLaserParams {
  double range_min = 0.02;     // m
  double range_max = 5.0;      // m; a return at or beyond it reads 0
  double sigma = 0.012;        // m, Gaussian range noise
  double resolution = 0.001;   // m, readings are rounded to this
  double dropout_near = 0.10;  // probability of a single dropout at range 0
  double dropout_far = 0.40;   // ... at range_max (linear in between)
  double burst_rate = 0.02;    // probability that a burst of dropouts starts at a beam
  double burst_mean = 5.0;     // mean burst length (beams; geometric)
  double short_rate = 0.003;   // probability of a random short return
};

/// Neato readings for ideal ranges (+inf: no return), beam by beam in scan order.
std::vector<float> neatoReadings(const std::vector<double>& ideal, const NeatoLaserParams& params,
                                 Random* random);

}  // namespace pf::sim
