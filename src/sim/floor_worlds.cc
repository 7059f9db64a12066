#include "pf_localization/sim/floor_worlds.h"

#include "pf_localization/core/map/floors_file.h"
#include "pf_localization/core/map/map_loader.h"

namespace pf::sim {

FloorWorlds FloorWorlds::load(const std::string& path) {
  FloorWorlds w;
  if (!isFloorsFile(path)) {
    w.grids.push_back(loadMap(path));
    return w;
  }
  const FloorsFile file = loadFloorsFile(path);
  for (const Floor& f : file.floors) {
    w.names.push_back(f.name);
    w.grids.push_back(loadMap(f.map));
  }
  w.initial = file.initial;
  return w;
}

std::size_t FloorWorlds::index(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return i;
  }
  return grids.size();
}

const OccupancyGrid* FloorWorlds::grid(const std::string& name) const {
  const std::size_t i = index(name);
  return i < grids.size() ? &grids[i] : nullptr;
}

}  // namespace pf::sim
