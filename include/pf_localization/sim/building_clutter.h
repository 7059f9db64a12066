// The third dimension of the building map (building_map.h): its ceiling and
// the things in it that are not on the map, at heights a 2D lidar at the
// usual 0.2-0.6 m never sees, or sees only in part. A filter that keeps the
// points of a height band of the base frame (roughly 0.3-0.9 m) must drop
// the floor, the ceiling and all of these but the table's legs:
//
//   what                                     where (map, m)         height (m)
//   two parcels on the corridor's south side x 4.6-5.0, 5.2-5.8     0-0.2
//                                            y 6.7-7.1
//   a pallet in the lobby                    x 7.2-8.4, y 3.8-4.6   0-0.15
//   a standing table in the lobby: a top     x 11.2-12.4, y 4.2-5.0 1.0-1.04
//     on four 0.04 m legs at its corners                            0-1.0
//   a wall cabinet over the corridor         x 13.0-14.5, y 8.1-8.5 1.2-1.8
//   a sign hanging across the corridor       x 6.5-6.53, y 6.9-8.3  2.0-2.5
//   a lamp hanging in the lobby              x 9.5-10.1, y 1.9-2.5  2.1-2.5
//
// The robot's paths stay clear of them (they are not on the map, so
// checkClearance cannot see them): the parcels and the cabinet are beside
// the corridor's middle line (y 7.6), the sign and the lamp are above the
// robot, the pallet and the table stand away from the lobby's route.
#pragma once

#include <vector>

#include "pf_localization/sim/scene_3d.h"

namespace pf::sim {

/// The building's ceiling, m above its floor.
inline constexpr double kBuildingCeiling = 2.5;

/// The objects in the table above.
std::vector<Box3> buildingClutter();

}  // namespace pf::sim
