#include "pf_localization/sim/building_map.h"

#include <algorithm>
#include <cmath>

namespace pf::sim {

namespace {

constexpr double kResolution = 0.05;
constexpr int8_t kFree = MapCanvas::kFree;
constexpr int8_t kWall = MapCanvas::kOccupied;
constexpr int8_t kUnknown = MapCanvas::kUnknown;

// Everything in a twin room is placed relative to its south-west interior
// corner, so that the two rooms cannot differ.
void drawTwinRoom(MapCanvas* c, double x0) {
  const double y0 = kTwinRoomA.y0;
  const auto rel = [&](double ax, double ay, double bx, double by) {
    return Box{x0 + ax, y0 + ay, x0 + bx, y0 + by};
  };
  c->fill(rel(0.0, 0.0, 4.6, 6.05), kFree);
  c->fill(rel(1.6, -0.15, 2.6, 0.0), kFree);  // door to the corridor
  c->fill(rel(2.4, 3.4, 3.6, 4.2), kWall);    // table
  c->fill(rel(0.0, 1.0, 0.5, 2.2), kWall);    // cabinet
  c->fill(rel(0.6, 5.25, 2.6, 6.05), kWall);  // sofa
}

}  // namespace

OccupancyGrid makeBuildingMap() {
  MapCanvas c({-1.0, -1.0, 21.0, 16.0}, kResolution);
  // The outline, solid; the north-east notch stays unknown.
  c.fill({0.0, 0.0, 20.0, 11.5}, kWall);
  c.fill({0.0, 11.5, 15.5, 15.0}, kWall);

  // Corridor and its doorways (walls at y 6.5-6.65 and 8.5-8.65).
  c.fill({0.3, 6.65, 19.7, 8.5}, kFree);
  c.fill({11.6, 8.5, 12.6, 8.65}, kFree);  // lab
  c.fill({17.0, 8.5, 18.0, 8.65}, kFree);  // office
  c.fill({2.5, 6.5, 3.5, 6.65}, kFree);    // kitchen
  c.fill({8.4, 6.5, 10.8, 6.65}, kFree);   // lobby, a wide opening
  c.fill({15.3, 6.5, 16.3, 6.65}, kFree);  // storage

  drawTwinRoom(&c, kTwinRoomA.x0);
  drawTwinRoom(&c, kTwinRoomB.x0);

  // Lab: four pillars and a long desk.
  c.fill({9.8, 8.65, 15.2, 14.7}, kFree);
  for (double px : {11.1, 13.5}) {
    for (double py : {10.4, 12.7}) c.fill({px, py, px + 0.4, py + 0.4}, kWall);
  }
  c.fill({10.2, 14.0, 12.6, 14.7}, kWall);

  // Office under the notch.
  c.fill({15.5, 8.65, 19.7, 11.2}, kFree);
  c.fill({18.4, 9.6, 19.7, 10.8}, kWall);  // desk

  // Kitchen: island, counter, and a wall stub from the west wall.
  c.fill({0.3, 0.3, 6.0, 6.5}, kFree);
  c.fill({2.0, 2.4, 4.0, 3.4}, kWall);
  c.fill({0.3, 0.3, 3.5, 0.9}, kWall);
  c.fill({0.3, 4.5, 1.5, 4.65}, kWall);

  // Lobby: a diagonal wall cuts off the south-west corner (never seen, so
  // unknown behind it), a round column, a bench.
  c.fill({6.15, 0.3, 13.0, 6.5}, kFree);
  c.triangle(6.15, 0.3, 8.3, 0.3, 6.15, 2.3, kUnknown);
  c.segment(6.15, 2.3, 8.3, 0.3, 0.2, kWall);
  c.disc(10.0, 3.2, 0.35, kWall);
  c.fill({11.0, 0.3, 12.6, 0.8}, kWall);

  // Storage: two shelves, and a locked closet in the south-east corner.
  c.fill({13.15, 0.3, 19.7, 6.5}, kFree);
  c.fill({14.0, 1.2, 14.4, 4.8}, kWall);
  c.fill({16.6, 1.2, 17.0, 4.8}, kWall);
  c.fill({17.85, 0.3, 19.7, 2.65}, kWall);
  c.fill({18.0, 0.3, 19.7, 2.5}, kUnknown);
  return c.grid();
}

OccupancyGrid makeUpperFloorMap() {
  MapCanvas c({-1.0, -1.0, 21.0, 16.0}, kResolution);
  c.fill({0.0, 0.0, 20.0, 11.5}, kWall);
  c.fill({0.0, 11.5, 15.5, 15.0}, kWall);
  c.fill(kLiftLobby, kFree);
  c.fill({17.6, 0.3, 19.7, 6.5}, kFree);    // server room
  c.fill({18.3, 6.5, 19.1, 6.65}, kFree);   // its door
  c.fill({17.6, 0.3, 19.7, 1.1}, kWall);    // a rack along its south wall
  c.fill({17.6, 8.65, 19.7, 11.2}, kFree);  // kitchenette
  c.fill({17.8, 8.5, 18.6, 8.65}, kFree);   // its door
  c.fill({19.0, 9.6, 19.7, 11.2}, kWall);   // counter

  // The open-plan office, its door to the lobby, desks in uneven rows.
  c.fill({0.3, 0.3, 17.45, 11.35}, kFree);
  c.fill({17.45, 7.0, 17.6, 8.2}, kFree);
  for (double x : {1.5, 4.3, 9.2, 12.0}) c.fill({x, 1.5, x + 1.6, 2.3}, kWall);
  for (double x : {2.1, 6.4, 11.0}) c.fill({x, 4.4, x + 1.6, 5.2}, kWall);
  for (double x : {1.2, 5.1, 13.4}) c.fill({x, 8.6, x + 0.8, 10.0}, kWall);
  c.disc(7.5, 7.3, 0.3, kWall);
  c.disc(14.6, 4.6, 0.3, kWall);
  c.segment(9.0, 6.8, 11.4, 9.9, 0.15, kWall);  // a partition at an angle
  c.fill({15.6, 0.3, 17.45, 1.4}, kWall);       // copier corner

  // Two meeting rooms north of the office, with their tables.
  c.fill({0.3, 11.5, 7.55, 14.7}, kFree);
  c.fill({7.7, 11.5, 15.2, 14.7}, kFree);
  c.fill({0.3, 11.35, 7.55, 11.5}, kWall);
  c.fill({7.7, 11.35, 15.2, 11.5}, kWall);
  c.fill({5.2, 11.35, 6.2, 11.5}, kFree);
  c.fill({8.5, 11.35, 9.5, 11.5}, kFree);
  c.fill({2.0, 12.6, 4.6, 13.6}, kWall);
  c.disc(11.8, 13.1, 0.7, kWall);
  return c.grid();
}

OccupancyGrid makeSmallMap() {
  MapCanvas c({-0.5, -0.5, 6.5, 4.5}, kResolution);
  c.fill({0.0, 0.0, 6.0, 4.0}, kWall);
  c.fill({0.15, 0.15, 5.85, 3.85}, kFree);
  c.fill({4.4, 3.05, 5.85, 3.85}, kWall);  // cabinet in the north-east corner
  c.disc(1.8, 1.2, 0.25, kWall);           // column
  c.fill({3.5, 0.15, 3.65, 1.5}, kWall);   // wall stub from the south wall
  return c.grid();
}

namespace {

// The corridor map's side rooms: interior x range and north or south of the
// corridor, with the door's x range in the wall between.
struct SideRoom {
  double x0, x1;
  bool north;
  double door_x0, door_x1;
};

constexpr SideRoom kCorridorRooms[] = {
    {5.2, 8.4, true, 7.2, 8.1},       // N1
    {7.9, 11.2, false, 9.9, 10.8},    // S1
    {14.8, 18.0, true, 15.1, 16.0},   // N2
    {19.5, 22.6, false, 20.1, 21.0},  // S2
};

// Closed doors set 0.2 m into the 0.3 m walls (x range, north or south).
struct Recess {
  double x0, x1;
  bool north;
  double depth;
};

constexpr Recess kCorridorRecesses[] = {
    {5.8, 6.7, false, 0.2},   {10.4, 11.3, true, 0.2},   {12.5, 13.4, true, 0.2},
    {13.7, 14.6, false, 0.2}, {17.2, 18.6, false, 0.25},  // alcove (a vending machine's)
    {19.6, 20.5, true, 0.2},
};

// Walls 0.3 m thick, unknown behind them (as in a map built by SLAM: a solid
// block would look like a room full of walls to a likelihood field).
void drawCorridorDoorsStretch(MapCanvas* c) {
  const Box& corridor = kCorridorInterior;
  c->fill({corridor.x0, corridor.y0 - 0.3, kCorridorFeaturelessFrom, corridor.y1 + 0.3}, kWall);
  for (const SideRoom& r : kCorridorRooms) {
    const double wall_y0 = r.north ? corridor.y1 : corridor.y0 - 0.3;
    const Box room =
        r.north ? Box{r.x0, corridor.y1 + 0.3, r.x1, 7.7} : Box{r.x0, 0.3, r.x1, corridor.y0 - 0.3};
    c->fill({room.x0 - 0.3, room.y0 - 0.3, room.x1 + 0.3, room.y1 + 0.3}, kWall);
    c->fill(room, kFree);
    c->fill({r.door_x0, wall_y0, r.door_x1, wall_y0 + 0.3}, kFree);
  }
  for (const Recess& r : kCorridorRecesses) {
    if (r.north) {
      c->fill({r.x0, kCorridorInterior.y1, r.x1, kCorridorInterior.y1 + r.depth}, kFree);
    } else {
      c->fill({r.x0, kCorridorInterior.y0 - r.depth, r.x1, kCorridorInterior.y0}, kFree);
    }
  }
  // A closed door flush with the north wall in a frame whose jambs stand
  // 0.1 m out, and a radiator along the south wall.
  c->fill({22.3, kCorridorInterior.y1 - 0.1, 22.45, kCorridorInterior.y1}, kWall);
  c->fill({23.35, kCorridorInterior.y1 - 0.1, 23.5, kCorridorInterior.y1}, kWall);
  c->fill({15.6, kCorridorInterior.y0, 16.8, kCorridorInterior.y0 + 0.1}, kWall);
}

}  // namespace

OccupancyGrid makeCorridorMap() {
  MapCanvas c(kCorridorExtent, kResolution);
  const Box& corridor = kCorridorInterior;
  // West end: a room the corridor opens into, with a table, a cabinet and a
  // column.
  c.fill({0.0, 0.0, corridor.x0 + 0.3, 8.0}, kWall);
  c.fill({0.3, 0.3, corridor.x0, 7.7}, kFree);
  c.fill({1.2, 5.5, 2.4, 6.3}, kWall);
  c.fill({0.3, 1.0, 0.8, 2.2}, kWall);
  c.disc(2.6, 1.8, 0.25, kWall);

  drawCorridorDoorsStretch(&c);

  // The featureless stretch: two plain walls, unknown behind them.
  c.fill({kCorridorFeaturelessFrom, corridor.y0 - 0.3, corridor.x1, corridor.y1 + 0.3}, kWall);

  // East end: a T-junction, its arms closed 3.5 m from the corridor's axis.
  c.fill({corridor.x1 - 0.3, 0.0, corridor.x1 + 2.5, 8.0}, kWall);
  c.fill({corridor.x1, 0.3, corridor.x1 + 2.2, 7.7}, kFree);

  c.fill(corridor, kFree);
  return c.grid();
}

}  // namespace pf::sim
