// pf_make_map: writes the package's own maps (building, its upper floor and the
// floors file naming both, small and corridor, see
// pf_localization/sim/building_map.h; warehouse, see warehouse_map.h) in the
// map_server format.
//
//   pf_make_map --out-dir maps
//
// The maps are drawn by code, not from a seed, so the output is the same
// bytes every time.
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "pf_localization/core/map/map_loader.h"
#include "pf_localization/sim/building_map.h"
#include "pf_localization/sim/warehouse_map.h"

namespace {

constexpr char kUsage[] =
    "usage: pf_make_map [--out-dir DIR]   (default: maps)\n"
    "writes DIR/building.yaml/.pgm, DIR/small.yaml/.pgm, DIR/corridor.yaml/.pgm and\n"
    "DIR/warehouse.yaml/.pgm, DIR/building_upper.yaml/.pgm and DIR/building_floors.yaml\n"
    "(the building's two floors)\n";

// The building's two floors (floors_file.h): the lift is at the ground
// floor corridor's east end.
constexpr char kFloors[] =
    "# The building's floors (include/pf_localization/core/map/floors_file.h), written by\n"
    "# pf_make_map: the ground floor is maps/building.yaml, the upper floor another layout\n"
    "# on the same outline (building_map.h); the lift stands at the ground floor\n"
    "# corridor's east end, (18.8, 7.6).\n"
    "floors:\n"
    "  - name: ground\n"
    "    map: building.yaml\n"
    "  - name: upper\n"
    "    map: building_upper.yaml\n"
    "initial_floor: ground\n";

}  // namespace

int main(int argc, char** argv) {
  std::string out_dir = "maps";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) {
      std::cout << kUsage;
      return 0;
    }
    if (std::strcmp(argv[i], "--out-dir") == 0 && i + 1 < argc) {
      out_dir = argv[++i];
    } else {
      std::cerr << "pf_make_map: unexpected argument '" << argv[i] << "'\n" << kUsage;
      return 2;
    }
  }
  try {
    pf::saveMap(pf::sim::makeBuildingMap(), out_dir + "/building.yaml");
    pf::saveMap(pf::sim::makeSmallMap(), out_dir + "/small.yaml");
    pf::saveMap(pf::sim::makeCorridorMap(), out_dir + "/corridor.yaml");
    pf::saveMap(pf::sim::makeWarehouseMap(), out_dir + "/warehouse.yaml");
    pf::saveMap(pf::sim::makeUpperFloorMap(), out_dir + "/building_upper.yaml");
    std::ofstream(out_dir + "/building_floors.yaml") << kFloors;
  } catch (const std::exception& e) {
    std::cerr << "pf_make_map: " << e.what() << "\n";
    return 1;
  }
  std::cout << "wrote " << out_dir << "/building.yaml, " << out_dir << "/small.yaml, " << out_dir
            << "/corridor.yaml, " << out_dir << "/warehouse.yaml, " << out_dir
            << "/building_upper.yaml and " << out_dir << "/building_floors.yaml\n";
  return 0;
}
