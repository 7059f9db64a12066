// The simulated world in three dimensions, for lidars that do not look
// along a plane.
//
// The 2D map's occupied cells are walls from the floor to the ceiling; the
// floor is the plane z = 0 and the ceiling the plane z = ceiling_height,
// both unbounded; objects that are not on the map are axis-aligned boxes at
// any height (parcels on the floor, a table top on thin legs, a cabinet on
// a wall, a sign hanging from the ceiling); the path script's people are
// upright cylinders standing on the floor. A ray is cast from a point along
// an azimuth (map frame, counterclockwise from x) and an elevation (up from
// the horizontal) and stops at the first of these it meets.
//
// The walls are found by the 2D ray caster along the ray's projection onto
// the floor, which is exact because a wall spans every height a ray can be
// at indoors: the ray meets it wherever its projection enters the cell.
// People are hit on their side only, which covers every ray from a sensor
// below the top of their heads (the 3D rig's lidar is at 0.6 m).
#pragma once

#include <limits>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/sim/path_script.h"
#include "pf_localization/sim/ray_caster.h"

namespace pf::sim {

/// An axis-aligned box in map coordinates, metres.
struct Box3 {
  double x0, y0, z0, x1, y1, z1;
};

/// What a ray hit.
enum class Surface { kNothing, kFloor, kCeiling, kWall, kObject, kPerson };

struct Hit {
  double range = std::numeric_limits<double>::infinity();  // m along the ray
  Surface surface = Surface::kNothing;
};

class Scene3D {
 public:
  /// `ceiling_height` may be +inf (no ceiling). Keeps copies of everything.
  Scene3D(const OccupancyGrid& map, double ceiling_height, std::vector<Box3> objects,
          std::vector<Person> people, double person_height = 1.7);

  /// The first surface along the ray from (x, y, z), within max_range
  /// (inclusive), `t` seconds into the run (where the people are then).
  Hit cast(double x, double y, double z, double azimuth, double elevation, double max_range,
           double t) const;

  double ceilingHeight() const { return ceiling_height_; }

 private:
  RayCaster walls_;
  double ceiling_height_;
  std::vector<Box3> objects_;
  std::vector<Person> people_;
  double person_height_;
};

/// Distance along the ray from (x, y, z) in the unit direction (dx, dy, dz)
/// to where it enters `box`; +inf when it misses it or starts inside it.
double castToBox(double x, double y, double z, double dx, double dy, double dz, const Box3& box);

}  // namespace pf::sim
