// A building's floors file: each floor's name and map (a map_server YAML),
// and the floor a robot starts on.
//
//   floors:
//     - name: ground
//       map: building.yaml          # relative paths: from the floors file's folder
//     - name: upper
//       map: building_upper.yaml
//   initial_floor: ground           # optional; default the first floor
//
// map_publisher publishes the current floor's map, pf_node keeps one
// prepared map per floor visited (ros/localizer/floors.h) and pf_simulator
// changes the world at a path script's ride. Reading the file reads no map:
// each is loaded (pf::loadMap) when it is first needed.
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pf {

/// A floors file that cannot be used. what() names the file and the field.
class FloorsFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Floor {
  std::string name;
  std::string map;  // the map_server YAML, resolved against the floors file's folder
};

struct FloorsFile {
  std::string file;  // as given, for messages
  std::vector<Floor> floors;
  std::size_t initial = 0;  // index into floors

  /// The index of the floor named `name`; none when there is no such floor.
  std::optional<std::size_t> find(const std::string& name) const;
  /// The floors' names, comma-separated, for messages.
  std::string names() const;
};

/// Reads `path`. Throws FloorsFileError when it cannot be read or parsed,
/// has no floors, a floor without a name or map, two floors of one name, a
/// map file that does not exist, or an initial_floor that is not a floor.
FloorsFile loadFloorsFile(const std::string& path);

/// Whether `path` reads as a floors file (YAML with a top-level 'floors')
/// rather than a map's YAML: a tool that takes either tells them apart.
/// False when it cannot be read or parsed (the map loader then says why).
bool isFloorsFile(const std::string& path);

}  // namespace pf
