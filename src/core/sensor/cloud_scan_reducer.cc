#include "pf_localization/core/sensor/cloud_scan_reducer.h"

#include <Eigen/LU>  // determinant()
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pf_localization/core/util/fast_math.h"
#include "pf_localization/core/util/parameter_table.h"

namespace pf {
namespace {

// A mounting's rotation may come from a float32 quaternion (tf over the
// wire), so orthonormality is checked to float precision, not double's.
constexpr double kRotationTolerance = 1e-6;

// Below this length the sensor's x axis is vertical and has no heading.
constexpr double kMinAxisProjection = 1e-9;

// m: a bin's range is the mean over its points within this of its nearest.
// The nearest alone is the one whose noise is most negative: with a 16-ring
// lidar's 1.5 cm noise and up to 40 points a bin it read 3.2 cm short of a
// 2D lidar at the same place (cloud.bag, median over the bins). 0.1 m keeps
// a table leg in front of a wall from being averaged with the wall.
constexpr double kSurfaceDepth = 0.1;

// Each bin's range: the mean distance of the points within kSurfaceDepth of
// its nearest (`nearest_d2`, squared; +inf: empty), NaN for an empty bin.
// `kept`: every kept point's bin and squared distance.
std::vector<float> surfaceRanges(const std::vector<std::pair<int, double>>& kept,
                                 const std::vector<double>& nearest_d2) {
  const std::size_t bins = nearest_d2.size();
  std::vector<double> sum(bins, 0.0);
  std::vector<int> count(bins, 0);
  for (const auto& [k, d2] : kept) {
    const double d = std::sqrt(d2);
    if (d <= std::sqrt(nearest_d2[k]) + kSurfaceDepth) {
      sum[k] += d;
      ++count[k];
    }
  }
  std::vector<float> ranges(bins, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t k = 0; k < bins; ++k) {
    if (count[k] > 0) ranges[k] = static_cast<float>(sum[k] / count[k]);
  }
  return ranges;
}

}  // namespace

SensorMount SensorMount::fromRpy(double x, double y, double z, double roll, double pitch,
                                 double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll);
  const double cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  SensorMount m;
  m.rotation << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,            //
      -sp, cp * sr, cp * cr;
  m.translation << x, y, z;
  return m;
}

std::optional<std::string> validateMount(const SensorMount& mount) {
  if (!mount.rotation.allFinite() || !mount.translation.allFinite()) {
    return "the sensor's mounting on the robot is not finite";
  }
  const double off = (mount.rotation.transpose() * mount.rotation - Eigen::Matrix3d::Identity())
                         .cwiseAbs()
                         .maxCoeff();
  if (off > kRotationTolerance || mount.rotation.determinant() < 0.0) {
    return "the sensor's mounting is not a rotation (R^T R differs from I by " + formatNumber(off) +
           ", det " + formatNumber(mount.rotation.determinant()) + ")";
  }
  return std::nullopt;
}

const ParameterTable<CloudScanParams>& cloudScanParameters() {
  using P = CloudScanParams;
  using I = ParamInfo;
  static const ParameterTable<P> table = {
      member(&P::min_height, I("cloud_min_height", "m",
                               "lowest base-frame height of a cloud point that is kept (the floor "
                               "and low clutter are below)")
                                 .in(Range::any())),
      member(&P::max_height, I("cloud_max_height", "m",
                               "highest base-frame height of a cloud point that is kept (the "
                               "ceiling and what hangs from it are above)")
                                 .in(Range::any())),
      member(&P::bin_width,
             I("cloud_bin_width", "rad", "width of the angular bins a cloud is reduced to")
                 .in(Range::closed(1e-3, M_PI / 4.0))),
      member(&P::min_range, I("cloud_min_range", "m",
                              "cloud points nearer the sensor's vertical axis are the robot itself")
                                .in(Range::atLeast(0.0))),
      member(&P::max_range,
             I("cloud_max_range", "m", "cloud points this far from the sensor's axis are not used")
                 .in(Range::above(0.0))),
  };
  return table;
}

void validate(const CloudScanParams& p) {
  checkRanges(cloudScanParameters(), p);
  requireParameter(p.max_height > p.min_height, "cloud_max_height", "> cloud_min_height",
                   p.max_height);
  requireParameter(p.max_range > p.min_range, "cloud_max_range", "> cloud_min_range", p.max_range);
}

CloudScanReducer::CloudScanReducer(const CloudScanParams& params) : params_(params) {
  validate(params_);
  // The small tolerance keeps 2 pi / (pi / 360) at 720 bins, not 721.
  bins_ = static_cast<int>(std::ceil(2.0 * M_PI / params_.bin_width - 1e-9));
}

CloudScan CloudScanReducer::reduce(const std::vector<CloudPoint>& points,
                                   const SensorMount& mount) const {
  if (const auto problem = validateMount(mount)) throw std::invalid_argument(*problem);
  const Eigen::Matrix3d& r = mount.rotation;
  const Eigen::Vector3d& t = mount.translation;

  // The scan's frame: at the sensor, level, heading along the sensor's x
  // axis projected onto the floor plane (the rotation's first column).
  const double axis = std::hypot(r(0, 0), r(1, 0));
  const double heading = axis > kMinAxisProjection ? std::atan2(r(1, 0), r(0, 0)) : 0.0;
  const double ch = std::cos(heading), sh = std::sin(heading);
  // A point's coordinates in that frame, straight from the sensor frame:
  // u, v horizontal (rows of Rz(-heading) R; the translation cancels, the
  // frame's origin being the sensor), z the base-frame height.
  const Eigen::RowVector3d row_u = ch * r.row(0) + sh * r.row(1);
  const Eigen::RowVector3d row_v = -sh * r.row(0) + ch * r.row(1);
  const Eigen::RowVector3d row_z = r.row(2);

  const double min_d2 = params_.min_range * params_.min_range;
  const double max_d2 = params_.max_range * params_.max_range;
  const double width = 2.0 * M_PI / bins_;
  const double bins_per_rad = 1.0 / width;
  constexpr double kEmpty = std::numeric_limits<double>::infinity();
  std::vector<double> nearest_d2(bins_, kEmpty);
  // Each kept point's bin and horizontal distance, for the second pass.
  std::vector<std::pair<int, double>> kept;
  kept.reserve(points.size());

  CloudScan out;
  CloudScanCounts& n = out.counts;
  n.points = points.size();
  for (const CloudPoint& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      ++n.not_finite;
      continue;
    }
    const double x = p.x, y = p.y, z = p.z;
    const double height = row_z(0) * x + row_z(1) * y + row_z(2) * z + t.z();
    if (height < params_.min_height) {
      ++n.below_band;
      continue;
    }
    if (height > params_.max_height) {
      ++n.above_band;
      continue;
    }
    const double u = row_u(0) * x + row_u(1) * y + row_u(2) * z;
    const double v = row_v(0) * x + row_v(1) * y + row_v(2) * z;
    const double d2 = u * u + v * v;
    if (d2 < min_d2) {
      ++n.too_near;
      continue;
    }
    if (d2 >= max_d2) {
      ++n.too_far;
      continue;
    }
    ++n.kept;
    // Bin k is centred on -pi + k * width: the half-bin shift rounds to the
    // nearest centre, and the bin past the last one, at +pi, is bin 0 at -pi.
    int k = static_cast<int>((fastAtan2(v, u) + M_PI) * bins_per_rad + 0.5);
    if (k >= bins_) k -= bins_;
    if (d2 < nearest_d2[k]) nearest_d2[k] = d2;
    kept.emplace_back(k, d2);
  }
  const std::vector<float> ranges = surfaceRanges(kept, nearest_d2);
  LaserScan& scan = out.scan;
  scan.angle_min = -M_PI;
  scan.angle_increment = width;
  scan.range_min = params_.min_range;
  scan.range_max = params_.max_range;
  scan.sensor_pose = {t.x(), t.y(), heading};
  scan.ranges = ranges;
  for (const float range : ranges) n.bins_filled += std::isfinite(range) ? 1 : 0;
  return out;
}

}  // namespace pf
