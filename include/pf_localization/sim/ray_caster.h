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
// The Neato model (neatoReadings) turns those ideal ranges into readings,
// after the real Neato recording in the AC109 arena, which loses ~39 % of
// its beams:
//   - nothing within range_max, or a dropout: 0.0, as the Neato reports it;
//   - fixed blind sectors, where the robot's own mast and posts hide the
//     laser: 16 % of the beams are never valid, and their neighbours are
//     valid only half the time;
//   - single dropouts, more likely at long range (weak returns), with
//     p = dropout_near + (dropout_far - dropout_near) (r / range_max)^2;
//     the real rate grows from ~15 % below 1 m to ~60 % near 4 m, but the
//     AC109 arena is small: the defaults are lower so that a run through the
//     package's building, where many beams find nothing within range_max,
//     loses about as many beams in total as the real bag;
//   - bursts of consecutive dropouts (dark or shiny patches);
//   - a small fraction of beams hit something that is not on the map and
//     return a uniformly random shorter range;
//   - Gaussian noise, then rounding to the Neato's 1 mm resolution.
#pragma once

#include <utility>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/sim/sim_random.h"

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
  double range_min = 0.02;    // m
  double range_max = 5.0;     // m; a return at or beyond it reads 0
  double sigma = 0.012;       // m, Gaussian range noise
  double resolution = 0.001;  // m, readings are rounded to this
  // Laser-frame angles (degrees, first and last beam inclusive) that never
  // return, and the dropout probability of the beam on either side of one.
  std::vector<std::pair<int, int>> blind_sectors = {{21, 24},   {69, 77},   {106, 107},
                                                    {145, 151}, {209, 213}, {219, 221},
                                                    {260, 265}, {294, 300}, {341, 353}};
  double blind_edge = 0.5;
  double dropout_near = 0.05;  // probability of a single dropout at range 0
  double dropout_far = 0.2;    // ... at range_max (quadratic in between)
  double burst_rate = 0.01;    // probability that a burst of dropouts starts at a beam
  double burst_mean = 5.0;     // mean burst length (beams; geometric)
  double short_rate = 0.003;   // probability of a random short return
};

/// Neato readings for ideal ranges (+inf: no return) of a full turn of
/// evenly spaced beams, the first at laser-frame angle 0.
std::vector<float> neatoReadings(const std::vector<double>& ideal, const NeatoLaserParams& params,
                                 SimRandom* random);

}  // namespace pf::sim
