// The worlds pf_simulator's robot drives in: one map, or a building's floors
// (a floors file, core/map/floors_file.h), each its own map. A path script's
// `floor NAME` (path_script.h) moves the robot onto another floor: the same
// map frame, another world for its sensors.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf::sim {

struct FloorWorlds {
  std::vector<std::string> names;  // one per grid; empty for a single map
  std::vector<OccupancyGrid> grids;
  std::size_t initial = 0;  // the floor the robot starts on

  /// `path`: a map's YAML (one world) or a floors file (every floor's map,
  /// starting on its initial floor). Throws pf::MapLoadError or
  /// pf::FloorsFileError.
  static FloorWorlds load(const std::string& path);
  bool isBuilding() const { return !names.empty(); }
  /// The index of floor `name`, or grids.size() when there is none.
  std::size_t index(const std::string& name) const;
  /// The grid of floor `name`; null when there is none.
  const OccupancyGrid* grid(const std::string& name) const;
};

}  // namespace pf::sim
