#include "pf_localization/sim/building_clutter.h"

namespace pf::sim {

std::vector<Box3> buildingClutter() {
  std::vector<Box3> boxes = {
      {4.6, 6.7, 0.0, 5.0, 7.0, 0.2},     // parcel
      {5.2, 6.7, 0.0, 5.8, 7.1, 0.2},     // parcel
      {7.2, 3.8, 0.0, 8.4, 4.6, 0.15},    // pallet
      {11.2, 4.2, 1.0, 12.4, 5.0, 1.04},  // table top
      {13.0, 8.1, 1.2, 14.5, 8.5, 1.8},   // wall cabinet
      {6.5, 6.9, 2.0, 6.53, 8.3, 2.5},    // hanging sign
      {9.5, 1.9, 2.1, 10.1, 2.5, 2.5},    // lamp
  };
  for (double x : {11.2, 12.36}) {
    for (double y : {4.2, 4.96}) boxes.push_back({x, y, 0.0, x + 0.04, y + 0.04, 1.0});  // legs
  }
  return boxes;
}

}  // namespace pf::sim
