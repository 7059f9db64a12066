// Every parameter of the localizer, read from one place, with the same names
// in config/pf.yaml, on the ROS parameter server and in pf_bag_runner's
// --params file. localizerParameters() is the table (core/parameter_table.h)
// that declares each one, its unit, range, description and amcl name, once:
// reading, checking, live reconfiguration, `pf_node --help` and the generated
// files (parameter_docs.h) all come from it. amcl's names for the same
// settings are accepted too (amcl_params.h), so that an amcl configuration
// works unchanged.
#pragma once

#include <ros/node_handle.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/sensor/cloud_scan_reducer.h"
#include "pf_localization/core/util/parameter_table.h"
#include "pf_localization/ros/params/param_source.h"

namespace pf_ros {

struct LocalizerConfig {
  std::string global_frame = "map";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  double transform_tolerance = 0.1;  // s the published map->odom is post-dated by
  // Hz: map -> odom is republished when 1 / rate s pass without one (amcl has
  // no such setting; 20 Hz keeps tf users within 2 / rate = 0.1 s of a fresh one).
  double tf_publish_rate = 20.0;
  bool tf_broadcast = true;
  // De-skewing (core/scan_deskew.h): each beam is placed from where the laser
  // was when it took it, using the scan's time_increment and the odometry's
  // velocity. Scans with time_increment 0 are used as they are. Off by
  // default: against the raw references at hand it does not help
  // (README.md, "De-skewing").
  bool deskew_scans = false;
  // Which beam the scan's header stamp is the time of: "first_beam" (ROS's
  // convention, sensor_msgs/LaserScan) or "last_beam" (drivers that stamp a
  // scan when it is complete).
  std::string scan_stamp = "first_beam";
  // The topics of the lidars, separated by spaces or commas (scanTopics()):
  // one, amcl's `scan`, or several, whose scans one update weighs together
  // (ScanLocalizer::processScan).
  std::string scan_topics = "scan";
  // The topics of 3D lidars and depth cameras (PointCloud2), the same way
  // (cloudTopics()); none by default. Their sensors come after the scan topics'.
  std::string cloud_topics = "";
  // How much each sensor counts, scan topics then cloud topics (scanWeights()):
  // the log-likelihood's factor.
  std::string scan_weights = "1";
  // How a 3D lidar's or depth camera's cloud becomes a scan (ScanLocalizer::processCloud).
  pf::CloudScanParams cloud;
  std::optional<pf::Pose2> initial_pose;  // none: global localization
  Eigen::Matrix3d initial_cov = Eigen::Vector3d(0.25, 0.25, 0.0685).asDiagonal();
  pf::ParticleFilterParams filter;

  // pf_node only: pf_bag_runner has neither topics to throttle nor a
  // parameter server to save to.
  double gui_publish_rate = -1.0;  // Hz limit of particlecloud; <= 0: after every update
  // Poses at most in a particlecloud message: a larger cloud is shown by a
  // systematic resample to this many (toPoseArray). 5000 poses are 280 kB, which
  // rviz draws at its rate; 500 000 would be 28 MB a message.
  int cloud_max_poses = 5000;
  // s an update may take (wall, p95): when > 0 the particle count is capped
  // so that it does (UpdateTimeGovernor); <= 0: off, max_particles alone.
  double max_update_time = 0.0;
  double save_pose_rate = 0.5;  // Hz the estimate is saved to ~initial_pose_*; <= 0: never
  // The file the layer of the map's changes is saved to with the pose
  // (map_changes_saver.h); empty: defaultMapChangesPath().
  std::string map_changes_file;
  bool first_map_only = false;  // keep the first map; ignore later ones on the map topic
  // A building's floors file (core/map/floors_file.h): the maps come from it,
  // not from the map topic, and change_floor moves between them (floors.h).
  std::string floors_file;
};

/// config.scan_topics as a list: the words between spaces and commas.
std::vector<std::string> scanTopics(const LocalizerConfig& config);
/// config.cloud_topics, the same way.
std::vector<std::string> cloudTopics(const LocalizerConfig& config);
/// Every sensor's topic, by its index: the scan topics, then the cloud topics.
std::vector<std::string> sensorTopics(const LocalizerConfig& config);

/// config.scan_weights, one per sensor (the last given repeated). Throws
/// std::invalid_argument naming scan_weights for a word that is not a number
/// in (0, 1], or none.
std::vector<double> scanWeights(const LocalizerConfig& config);

/// Every parameter of LocalizerConfig, the filter's included, in the order of
/// config/pf.yaml: amcl's and what a robot, its sensors or a building needs.
const pf::ParameterTable<LocalizerConfig>& localizerParameters();

/// Where pf_node saves the signature of the map its saved pose is on (state
/// on the parameter server beside ~initial_pose_*, not a setting).
constexpr const char* kSavedPoseMapParam = "saved_pose_map";

/// What readConfig has to tell besides errors: amcl parameters that are
/// ignored and why, a setting given under both names, unknown names.
struct ConfigNotes {
  std::vector<std::string> warnings;
  std::vector<std::string> infos;
};

/// Reads every parameter (absent ones keep their defaults) and validates the
/// result. Throws std::invalid_argument naming the parameter and its valid range.
///
/// Each setting is looked up under our name, then under amcl's (odom_frame_id,
/// kld_z, ...): in `source` first, then in `defaults` (optional). So amcl's
/// name in `source` overrides our name in `defaults`, which is how
/// launch/amcl_compatible.launch puts config/pf.yaml under an amcl
/// configuration. Both names in the same source: ours wins, with a warning.
///
/// `notes` receives the warnings and information for the user; without it
/// they are logged through rosconsole.
LocalizerConfig readConfig(const ParamSource& source, const ParamSource* defaults = nullptr,
                           ConfigNotes* notes = nullptr);

/// The checks readConfig ends with (the table's ranges, then pf::validate), for
/// a configuration changed while running (dynamic_reconfigure): throws
/// std::invalid_argument with the same message ("invalid parameter NAME = V:
/// must be RANGE") that refuses it at start-up.
void validate(const LocalizerConfig& config);

}  // namespace pf_ros
