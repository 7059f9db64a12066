// Loads maps in the map_server format: a YAML file naming an image (PGM P2/P5
// greyscale or PPM P3/P6 colour, channels averaged) and its resolution, origin,
// negate flag, occupied/free thresholds and mode (trinary, scale or raw).
// The conversion from pixel to cell value follows map_server exactly, so a map
// loaded here equals the one map_server would have published.
#pragma once

#include <stdexcept>
#include <string>

#include "pf_localization/core/occupancy_grid.h"

namespace pf {

/// A malformed map file. what() names the file and the field or byte offset.
class MapLoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class MapMode { kTrinary, kScale, kRaw };

struct MapMetadata {
  std::string image;  // as resolved: relative paths are taken from the YAML's folder
  double resolution = 0.0;
  Pose2 origin;
  bool negate = false;
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  MapMode mode = MapMode::kTrinary;
};

/// Parses a map_server YAML file. Throws MapLoadError.
MapMetadata loadMapMetadata(const std::string& yaml_path);

/// Loads the image named by `meta` and converts it to cell values. Throws MapLoadError.
OccupancyGrid loadMapImage(const MapMetadata& meta);

/// loadMapImage(loadMapMetadata(yaml_path)).
OccupancyGrid loadMap(const std::string& yaml_path);

/// Writes a grid as a trinary map_server pair (PGM P5 + YAML): occupied 0,
/// free 254, unknown 205, the values map_server's map_saver uses.
/// `yaml_path`'s image is written next to it with the same stem and ".pgm".
void saveMap(const OccupancyGrid& grid, const std::string& yaml_path);

}  // namespace pf
