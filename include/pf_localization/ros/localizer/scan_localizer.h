// The ROS-message-level localizer that every front door shares: pf_node
// drives it from subscriptions, pf_bag_runner from a bag read as fast as the
// CPU allows. It owns the particle filter, looks the laser's mounting and the
// odometry at each scan's stamp up in a tf2::BufferCore, and says what to
// publish.
#pragma once

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2/buffer_core.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/map/map_change_layer.h"
#include "pf_localization/core/sensor/sensor_health.h"
#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {

/// Why a scan did not reach the filter.
enum class ScanError {
  kNone,             // it did (report says what the filter made of it)
  kNoMap,            // no map has arrived yet
  kEmptyLaserFrame,  // the scan's frame_id is empty: nothing to place the laser by
  kNoLaserMounting,  // tf has no base -> laser transform (the laser's mounting)
  kNoOdometry,       // tf has no odom -> base transform at the scan's stamp
  kBadCloud,         // a point cloud that cannot be read (point_cloud.h: which field, which type)
};

/// A few words for `error`, e.g. "no odometry at the scan's stamp".
const char* toString(ScanError error);

/// What processing one scan produced.
struct ScanResult {
  pf::UpdateReport report;             // report.updated: the filter ran
  ScanError error = ScanError::kNone;  // not kNone: the scan was not used, and why
  std::string error_detail;            // the specifics, for the log: which transform is missing
  std::string warning;                 // non-empty: the scan was used, but something in it is off
  // The odometry pose (odom -> base) at the scan's stamp, when it was found.
  std::optional<pf::Pose2> odom;
};

class ScanLocalizer {
 public:
  /// `tf` must outlive the localizer; it is only read from. Throws
  /// std::invalid_argument for an invalid configuration.
  ScanLocalizer(const LocalizerConfig& config, const tf2::BufferCore* tf);

  const LocalizerConfig& config() const { return config_; }
  const pf::ParticleFilter& filter() const { return filter_; }
  /// Each sensor's rate, age and beams, named by sensorTopics() (a sensor
  /// index beyond those as "sensor N", once it gave a scan).
  const pf::SensorHealth& sensorHealth() const { return health_; }
  pf::ParticleFilter& filter() { return filter_; }

  /// Installs or replaces the map. On the first map the filter is initialised
  /// from the configured initial pose, or globally when there is none.
  /// Returns an error message (empty on success).
  std::string setMap(const nav_msgs::OccupancyGrid& map);
  /// The same for a map already in the core's form, in `frame_id` (empty:
  /// the global frame), moved into the filter: a map loaded from a file
  /// needs no message (pf_bag_runner).
  std::string setMap(pf::OccupancyGrid grid, const std::string& frame_id = "");

  /// A map checked and built apart from the localizer (prepareMap), for
  /// setMap(ReadyMap) to install at once.
  struct ReadyMap {
    std::string error;  // why the map was refused; empty when `map` is ready
    std::optional<pf::PreparedMap> map;
    nav_msgs::MapMetaData info;  // as map-change messages carry it
  };
  /// What prepareMap needs from a localizer, copied with the filter's lock held.
  struct MapRecipe {
    pf::PreparedMap::Recipe filter;
    std::string global_frame;
  };
  MapRecipe mapRecipe() const { return {filter_.mapRecipe(), config_.global_frame}; }
  /// setMap's checks and the seconds a large map takes to build, reading no
  /// localizer: they run on any thread while updates go on with the current
  /// map (pf_node's map topic and set_map).
  static ReadyMap prepareMap(const nav_msgs::OccupancyGrid& map, const MapRecipe& recipe);
  static ReadyMap prepareMap(pf::OccupancyGrid grid, const std::string& frame_id,
                             const MapRecipe& recipe);
  /// Installs a prepared map as setMap above does; `map.error` when it was
  /// refused. `replaced`: where the map it replaces goes, with what its
  /// change layer learned (ParticleFilter::releaseMap); null: it is dropped.
  std::string setMap(ReadyMap map, std::optional<pf::PreparedMap>* replaced = nullptr);

  /// Told of every filter update's odometry, scans and stamp, after it: a
  /// search on other maps follows the same scans (floors.h).
  using UpdateObserver = std::function<void(const pf::Pose2& odom, const pf::ScanGroup& scans,
                                            const ros::Time& stamp)>;
  /// Empty: none (the default).
  void observeUpdates(UpdateObserver observer) { observer_ = std::move(observer); }

  /// Re-initialises around a pose given in the global frame, moved on by the
  /// odometry since its stamp (movedByOdometrySince). A pose in another
  /// frame must be transformed by the caller (pf_node does, via tf).
  /// Returns an error message (empty on success).
  std::string setInitialPose(const geometry_msgs::PoseWithCovarianceStamped& pose);

  /// Global localization: particles spread over the map's free space.
  std::string startGlobalLocalization();

  /// Starts over as on the first map: from the initial pose of the
  /// configuration (not one set since), or globally without one. For time
  /// jumping back, as when a bag is replayed with --loop.
  std::string restart();

  /// Puts the live parameters of `config` (live_params.h) in effect from the
  /// next update on, keeping the particles and the estimate. Returns an error
  /// message (empty on success); on error nothing changed.
  std::string reconfigure(const LocalizerConfig& config);

  /// Uses one scan of sensor `sensor` (0 for the only one; an index per scan
  /// topic): odometry and laser pose from tf at the scan's stamp (and, to
  /// de-skew it, the odometry one sweep earlier), then the filter update.
  /// With several sensors the update also takes the latest scan of each
  /// other sensor that arrived since the last update and is at most
  /// kMaxSensorScanAge older, placed where the robot was at its stamp by the
  /// odometry (core/scan_group.h): two half views score as one full view.
  ScanResult processScan(const sensor_msgs::LaserScan& scan, std::size_t sensor = 0);

  /// The same for a 3D lidar's or a depth camera's cloud of sensor `sensor`
  /// (an index of its own, after the scan topics'): reduced to a scan by
  /// config().cloud (core/cloud_scan_reducer.h) from its 3D mounting in tf, then
  /// weighed like any other sensor's scan.
  ScanResult processCloud(const sensor_msgs::PointCloud2& cloud, std::size_t sensor);

  /// map -> odom to publish, stamped `stamp` (the caller adds transform_tolerance):
  /// the filter's, or between an initial pose and the first update after it,
  /// the one that pose gives with the latest odometry (as amcl keeps
  /// publishing through a re-initialisation; none when tf has no odometry).
  std::optional<geometry_msgs::TransformStamped> mapToOdom(const ros::Time& stamp) const;
  /// The estimate with covariance, stamped `stamp`, in the global frame.
  std::optional<geometry_msgs::PoseWithCovarianceStamped> estimate(const ros::Time& stamp) const;
  /// The particles, stamped `stamp`, in the global frame.
  geometry_msgs::PoseArray particleCloud(const ros::Time& stamp) const;

  /// Where the world no longer matches the map (ParticleFilter::mapChanges()).
  /// Null before a map; a new map starts it anew.
  const pf::MapChangeLayer* mapChanges() const { return filter_.mapChanges(); }
  /// That layer over the map as an OccupancyGrid (MapChangeLayer::occupancy()),
  /// stamped `stamp`; none before a map.
  std::optional<nav_msgs::OccupancyGrid> mapChangesMsg(const ros::Time& stamp) const;
  /// The same into `msg`, whose storage is used again; false before a map.
  bool mapChangesMsg(const ros::Time& stamp, nav_msgs::OccupancyGrid* msg) const;
  /// At most `max_poses` of them (0: all), a systematic resample by weight
  /// when there are more (toPoseArray in conversions.h).
  geometry_msgs::PoseArray particleCloud(const ros::Time& stamp, std::size_t max_poses) const;

 private:
  // tf's mounting of `frame` on the base and the odometry at `stamp`, into
  // `result` (its error when either is missing).
  std::optional<geometry_msgs::TransformStamped> lookUp(const std::string& frame,
                                                        const ros::Time& stamp,
                                                        ScanResult* result) const;
  // The filter update on `scan` of `sensor` with the other sensors' latest.
  void update(pf::LaserScan scan, std::size_t sensor, const ros::Time& stamp, ScanResult* result);

  // Records `scan` of `sensor` in health_.
  void observeHealth(const pf::LaserScan& scan, std::size_t sensor, const ros::Time& stamp);

  // A sensor's latest scan, as the filter takes it, and the odometry at its stamp.
  struct SensorScan {
    pf::LaserScan scan;
    pf::Pose2 odom;
    ros::Time stamp;
    bool used = false;  // by an update already: the next one does not take it again
  };

  LocalizerConfig config_;
  const std::optional<pf::Pose2> configured_pose_;
  const Eigen::Matrix3d configured_cov_;
  const tf2::BufferCore* tf_;
  pf::ParticleFilter filter_;
  std::optional<pf::Pose2> given_map_to_odom_;  // mapToOdom() from the last initial pose
  bool had_map_ = false;
  nav_msgs::MapMetaData map_info_;                 // of the map in use
  std::vector<std::optional<SensorScan>> latest_;  // per sensor
  std::vector<pf::LaserScan> group_;               // the scans of the current update
  pf::CloudScanReducer cloud_reducer_;
  pf::SensorHealth health_;
  std::vector<double> weights_;               // of sensorTopics()' sensors (scan_weights)
  std::vector<pf::CloudPoint> cloud_points_;  // scratch of processCloud
  UpdateObserver observer_;
};

/// s: a scan of another sensor older than this is not used (a sensor that
/// fell silent). The odometry carries it over that time to within
/// millimetres; two of the slowest lidars' periods (5 Hz) still fit.
constexpr double kMaxSensorScanAge = 0.5;

/// The log line for a scan that was not used: the error and its detail.
std::string errorMessage(const ScanResult& result);

/// What is inconsistent in a scan message without making it unusable:
/// intensities of another length than the ranges (they are not used), or an
/// angle_max that disagrees with angle_min + (n - 1) * angle_increment (the
/// beams are placed by angle_min and angle_increment, as every ROS consumer
/// does). Empty when the message is consistent.
std::string scanInconsistency(const sensor_msgs::LaserScan& scan);

/// When each beam of `scan` was taken relative to its stamp (by
/// `config.scan_stamp`), and the base's velocity then: the odometry's motion
/// over the sweep that ends at the stamp, from `odom_at_stamp` and tf one
/// sweep earlier. Still (no correction) when config.deskew_scans is off, the
/// scan has no beam timing (time_increment 0) or an implausible one (a sweep
/// over a second), or tf has no odometry that far back.
pf::SweepMotion sweepMotion(const sensor_msgs::LaserScan& scan, const tf2::BufferCore& tf,
                            const LocalizerConfig& config, const pf::Pose2& odom_at_stamp);

/// A nav_msgs/Odometry as the odom -> base transform it describes, for a tf
/// buffer that has no odometry on /tf (bags that only record /odom).
geometry_msgs::TransformStamped odometryToTransform(const nav_msgs::Odometry& odom);

}  // namespace pf_ros
