#include "pf_localization/sim/ring_lidar.h"

#include <limits>

namespace pf::sim {

float surfaceIntensity(Surface surface) {
  switch (surface) {
    case Surface::kFloor:
      return 10.0f;
    case Surface::kCeiling:
      return 30.0f;
    case Surface::kWall:
      return 60.0f;
    case Surface::kObject:
      return 100.0f;
    case Surface::kPerson:
      return 40.0f;
    case Surface::kNothing:
      break;
  }
  return 0.0f;
}

std::vector<RingPoint> ringSweep(const RingLidar& lidar, const Scene3D& scene, const Pose2& base,
                                 double t, SimRandom* random) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const Pose2 sensor = compose(base, lidar.mount);
  std::vector<double> cos_az(lidar.columns), sin_az(lidar.columns);
  for (int c = 0; c < lidar.columns; ++c) {
    cos_az[c] = std::cos(lidar.azimuth(c));
    sin_az[c] = std::sin(lidar.azimuth(c));
  }
  std::vector<RingPoint> points(static_cast<std::size_t>(lidar.rings) * lidar.columns);
  for (int r = 0; r < lidar.rings; ++r) {
    const double el = lidar.elevation(r);
    const double ce = std::cos(el), se = std::sin(el);
    for (int c = 0; c < lidar.columns; ++c) {
      const Hit hit = scene.cast(sensor.x, sensor.y, lidar.height, sensor.yaw + lidar.azimuth(c),
                                 el, lidar.range_max, t);
      // Both draws for every ray, so that one ray's world does not shift the
      // noise of the others.
      const bool dropped = random->uniform() < lidar.dropout;
      const double range = hit.range + random->gaussian(lidar.sigma);
      RingPoint& p = points[static_cast<std::size_t>(r) * lidar.columns + c];
      if (hit.surface == Surface::kNothing || dropped || range < lidar.range_min ||
          range > lidar.range_max) {
        p = {kNaN, kNaN, kNaN, 0.0f};
        continue;
      }
      p = {static_cast<float>(range * ce * cos_az[c]), static_cast<float>(range * ce * sin_az[c]),
           static_cast<float>(range * se), surfaceIntensity(hit.surface)};
    }
  }
  return points;
}

}  // namespace pf::sim
