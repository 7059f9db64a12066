// Loads maps in the map_server format: a YAML file naming an image (PGM P2/P5
// greyscale or PPM P3/P6 colour, channels averaged) and its resolution, origin,
// negate flag, occupied/free thresholds and mode (trinary, scale or raw).
// The conversion from pixel to cell value follows ROS 1 (Noetic) map_server's
// image_loader.cpp, so a map loaded here equals the one map_server would have
// published:
//   avg = mean of the channels (each 0..255), then avg = 255 - avg if negate;
//   raw:  value = (uint8) avg, stored as int8 (so 200 reads back as -56);
//   else p = (255 - avg) / 255 and value = 100 if p > occupied_thresh,
//        0 if p < free_thresh, otherwise -1 (trinary) or
//        (int)(1 + 98 * (p - free) / (occupied - free)) (scale).
// Samples with a maxval other than 255 (up to 16-bit) are first rescaled to
// 0..255 with rounding. The first image row is the top of the map, grid row 0
// the bottom. No image library: PNG and other formats are rejected.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

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

/// Parses and validates a map_server YAML file (image, resolution and origin
/// required; negate, occupied_thresh, free_thresh and mode optional with
/// map_server's defaults). Throws MapLoadError: "<yaml>: field '<name>' ...".
MapMetadata loadMapMetadata(const std::string& yaml_path);

/// Loads the image named by `meta` and converts it to cell values.
/// Throws MapLoadError: "<image>: <what is wrong>".
OccupancyGrid loadMapImage(const MapMetadata& meta);

/// loadMapImage(loadMapMetadata(yaml_path)); image errors are prefixed with
/// "<yaml>: field 'image': " so the message leads to the file to fix.
OccupancyGrid loadMap(const std::string& yaml_path);

/// Writes a grid as a trinary map_server pair (PGM P5 + YAML): occupied 0,
/// free 254, unknown 205, the values map_server's map_saver uses, chosen by
/// OccupancyGrid::classify(). With the thresholds written (0.65, 0.196) they
/// load back as 100, 0 and -1, so loadMap(saveMap(g)) == g for trinary grids.
/// `yaml_path`'s image is written next to it with the same stem and ".pgm",
/// and the YAML names it relatively. Throws std::invalid_argument for an empty
/// grid and std::runtime_error when a file cannot be written.
void saveMap(const OccupancyGrid& grid, const std::string& yaml_path);

/// The same pair with `pixels` in the image (row-major from the lower-left
/// cell, as grid.data()) instead of the grid's classification: a layer over
/// the map (map_change_layer.h) with `grid`'s size, resolution and origin.
/// Throws std::invalid_argument when `pixels` is not one per cell.
void saveImage(const OccupancyGrid& grid, const std::vector<std::uint8_t>& pixels,
               const std::string& yaml_path);

}  // namespace pf
