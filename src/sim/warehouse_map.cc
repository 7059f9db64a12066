#include "pf_localization/sim/warehouse_map.h"

namespace pf::sim {

namespace {

constexpr double kResolution = 0.05;
constexpr int8_t kFree = MapCanvas::kFree;
constexpr int8_t kWall = MapCanvas::kOccupied;

constexpr double kFirstRowY = 12.0;  // row 0's south face: the staging area's north edge
// Across a row, from its south face: the four lines of uprights (south
// rack's front and back, north rack's back and front) and the flue's mesh.
constexpr double kUprightLines[] = {0.0, 1.0, 1.3, 2.3};
constexpr double kMeshFrom = 1.15, kMeshTo = 1.25;

// West edges of the loading dock's door recesses in the south wall,
// irregularly spaced so that no two stretches of the dock look alike.
constexpr double kDockDoorX[] = {14.0, 19.0, 24.0, 33.0, 38.0, 52.0, 57.0, 71.0};
constexpr double kDockDoorWidth = 3.0;
constexpr double kPillarY = 7.0;
constexpr double kPillarX[] = {20.0, 40.0, 60.0, 80.0, 100.0};
constexpr double kPillarSide = 0.5;

// Everything in a row is placed relative to its segment's south-west corner,
// so that the rows and the segments cannot differ.
void drawRackSegment(MapCanvas* c, double x0, double y0) {
  for (int bay = 0; bay <= kWarehouseBays; ++bay) {
    const double x = x0 + bay * kWarehouseBayPitch;
    for (double dy : kUprightLines) {
      c->fill({x, y0 + dy, x + kWarehouseUpright, y0 + dy + kWarehouseUpright}, kWall);
    }
  }
  c->fill({x0, y0 + kMeshFrom, x0 + kWarehouseSegmentLength, y0 + kMeshTo}, kWall);
}

void drawLoadingDock(MapCanvas* c) {
  // Each door is a recess 0.6 m deep through the 0.3 m wall, closed by a
  // roll-up door 0.3 m thick behind it.
  const double wall_y = kWarehouseInterior.y0;
  for (double x : kDockDoorX) {
    c->fill({x - 0.3, wall_y - 0.9, x + kDockDoorWidth + 0.3, wall_y}, kWall);
    c->fill({x, wall_y - 0.6, x + kDockDoorWidth, wall_y}, kFree);
  }
}

void drawOffice(MapCanvas* c) {
  // The north-east corner, walled off by 0.15 m walls with a 1 m door; a
  // desk and a cabinet inside.
  const Box& in = kWarehouseInterior;
  const double x0 = 100.0, y0 = 71.0;
  c->fill({x0, y0, in.x1, y0 + 0.15}, kWall);
  c->fill({x0, y0, x0 + 0.15, in.y1}, kWall);
  c->fill({104.0, y0, 105.0, y0 + 0.15}, kFree);    // door
  c->fill({108.0, 74.0, 110.0, 75.0}, kWall);       // desk
  c->fill({x0 + 0.15, 76.5, 103.0, in.y1}, kWall);  // cabinet
}

}  // namespace

double warehouseRowY(int row) { return kFirstRowY + row * kWarehouseRowPitch; }

Box warehouseAisle(int aisle) {
  return {kWarehouseSegmentX[0], warehouseRowY(aisle - 1) + kWarehouseRowDepth,
          kWarehouseSegmentX[2] + kWarehouseSegmentLength, warehouseRowY(aisle)};
}

OccupancyGrid makeWarehouseMap() {
  MapCanvas c(kWarehouseExtent, kResolution);
  const Box& in = kWarehouseInterior;
  c.fill({in.x0 - 0.3, in.y0 - 0.3, in.x1 + 0.3, in.y1 + 0.3}, kWall);
  c.fill(in, kFree);
  for (int row = 0; row < kWarehouseRows; ++row) {
    for (double x0 : kWarehouseSegmentX) drawRackSegment(&c, x0, warehouseRowY(row));
  }
  drawLoadingDock(&c);
  for (double x : kPillarX) {
    c.fill({x, kPillarY, x + kPillarSide, kPillarY + kPillarSide}, kWall);
  }
  drawOffice(&c);
  return c.grid();
}

std::vector<Box3> warehousePallets() {
  constexpr double kHeight = 1.2;
  return {
      {20.0, 25.3, 0.0, 21.2, 26.1, kHeight},  // aisle 3, against row 2's face
      {60.0, 49.0, 0.0, 61.2, 49.8, kHeight},  // aisle 7, against row 7's face
      {40.0, 30.0, 0.0, 40.8, 31.2, kHeight},  // cross aisle 1, by its west side
      {45.0, 3.0, 0.0, 46.2, 3.8, kHeight},    // staging area, two side by side
      {46.5, 3.0, 0.0, 47.7, 3.8, kHeight},
  };
}

}  // namespace pf::sim
