#include "pf_localization/sim/planar_lidar.h"

#include <algorithm>

namespace pf::sim {

std::vector<double> idealRanges(const PlanarLidar& lidar, const RayCaster& walls,
                                const std::vector<Person>& people, const Pose2& base, double t) {
  const Pose2 sensor = lidar.poseIn(base);
  std::vector<double> ideal(lidar.beams);
  for (int i = 0; i < lidar.beams; ++i) {
    const double angle = sensor.yaw + (lidar.angle_min + i * lidar.angle_increment);
    double r = walls.cast(sensor.x, sensor.y, angle, lidar.range_max);
    for (const Person& p : people) {
      double px, py;
      p.positionAt(t, &px, &py);
      r = std::min(r, castToCircle(sensor.x, sensor.y, angle, px, py, p.radius));
    }
    ideal[i] = r;
  }
  return ideal;
}

std::vector<double> idealRanges(const PlanarLidar& lidar, const Scene3D& scene, const Pose2& base,
                                double t) {
  const Pose2 sensor = lidar.poseIn(base);
  std::vector<double> ideal(lidar.beams);
  for (int i = 0; i < lidar.beams; ++i) {
    const double angle = sensor.yaw + (lidar.angle_min + i * lidar.angle_increment);
    ideal[i] = scene.cast(sensor.x, sensor.y, lidar.height, angle, 0.0, lidar.range_max, t).range;
  }
  return ideal;
}

}  // namespace pf::sim
