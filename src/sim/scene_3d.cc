#include "pf_localization/sim/scene_3d.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace pf::sim {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

Scene3D::Scene3D(const OccupancyGrid& map, double ceiling_height, std::vector<Box3> objects,
                 std::vector<Person> people, double person_height)
    : walls_(map),
      ceiling_height_(ceiling_height),
      objects_(std::move(objects)),
      people_(std::move(people)),
      person_height_(person_height) {}

double castToBox(double x, double y, double z, double dx, double dy, double dz, const Box3& box) {
  // Slabs: the ray is inside the box between the latest entry into and the
  // earliest exit from the three pairs of parallel planes.
  double enter = -kInf, leave = kInf;
  const double origin[3] = {x, y, z}, dir[3] = {dx, dy, dz};
  const double lo[3] = {box.x0, box.y0, box.z0}, hi[3] = {box.x1, box.y1, box.z1};
  for (int k = 0; k < 3; ++k) {
    if (dir[k] == 0.0) {
      if (origin[k] < lo[k] || origin[k] > hi[k]) return kInf;
      continue;
    }
    double a = (lo[k] - origin[k]) / dir[k], b = (hi[k] - origin[k]) / dir[k];
    if (a > b) std::swap(a, b);
    enter = std::max(enter, a);
    leave = std::min(leave, b);
  }
  if (enter > leave || leave < 0.0 || enter <= 0.0) return kInf;  // missed, behind, or inside
  return enter;
}

Hit Scene3D::cast(double x, double y, double z, double azimuth, double elevation, double max_range,
                  double t) const {
  const double ce = std::cos(elevation), se = std::sin(elevation);
  const double dx = ce * std::cos(azimuth), dy = ce * std::sin(azimuth);
  Hit hit;
  hit.range = max_range;
  const auto take = [&](double range, Surface surface) {
    if (range <= hit.range && range < kInf) hit = {range, surface};
  };
  if (se < 0.0) take(-z / se, Surface::kFloor);
  if (se > 0.0) take((ceiling_height_ - z) / se, Surface::kCeiling);
  // Walls: only as far as the floor or the ceiling lets the ray go.
  if (ce > 0.0) take(walls_.cast(x, y, azimuth, hit.range * ce) / ce, Surface::kWall);
  for (const Box3& box : objects_) take(castToBox(x, y, z, dx, dy, se, box), Surface::kObject);
  if (ce > 0.0) {
    for (const Person& p : people_) {
      double px, py;
      p.positionAt(t, &px, &py);
      const double range = castToCircle(x, y, azimuth, px, py, p.radius) / ce;
      const double at = z + range * se;
      if (at >= 0.0 && at <= person_height_) take(range, Surface::kPerson);
    }
  }
  if (hit.surface == Surface::kNothing) hit.range = kInf;
  return hit;
}

}  // namespace pf::sim
