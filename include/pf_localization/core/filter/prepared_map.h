// A map made ready for the filter: every structure an update reads from a
// map, built apart from the filter and swapped in at once
// (ParticleFilter::setMap).
//
// Building is the expensive part of a new map: a distance transform of every
// cell (and a second one inside thick obstacles), the likelihood tables of
// the scans expected, the screening's rays and change layer, and the search
// for look-alike places; seconds on a 200 x 600 m floor. It reads nothing an
// update changes, only a Recipe copied from the filter, so a node can build a
// new map on one thread while updates go on with the current one and publish
// map -> odom from it, and hold the filter only for the swap
// (docs/how-it-works/map.md, "A new map").
#pragma once

#include <memory>
#include <vector>

#include "pf_localization/core/filter/beam_screen.h"
#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/recovery/look_alikes.h"
#include "pf_localization/core/sensor/sensor_model.h"

namespace pf {

struct PreparedMap {
  /// What building needs from the filter (ParticleFilter::mapRecipe): its
  /// parameters, and the range_max values of the scans it expects, whose
  /// likelihood tables are built with the map.
  struct Recipe {
    ParticleFilterParams params;
    std::vector<double> ranges;
  };

  /// Builds every structure for `grid` (moved in: the model's field keeps
  /// it). Throws std::invalid_argument for an empty map or an out-of-range
  /// sensor parameter.
  static PreparedMap build(OccupancyGrid grid, const Recipe& recipe);

  std::unique_ptr<SensorModel> model;   // the distance field, the grid in it, the tables
  BeamScreen::MapParts screen;          // the judging's rays, and an empty change layer
  std::vector<MapSymmetry> symmetries;  // the look-alike places (look_alikes.h)
  ParticleFilterParams params;          // the recipe's: what the model was built with
};

}  // namespace pf
