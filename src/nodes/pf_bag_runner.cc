// pf_bag_runner: runs the localizer over a recorded bag as fast as the CPU
// allows (or at the bag's own pace, --pace), with no ROS master: the bag is
// read with the rosbag C++ API, tf is rebuilt in a tf2::BufferCore from the
// bag's /tf and /tf_static, and the very same ScanLocalizer that pf_node uses
// does the work.
//
// Writes the estimate at every scan in TUM format (t x y z qx qy qz qw): the
// newest map -> odom composed with the odometry at the scan's stamp, which is
// exactly the pose a tf user would get from pf_node at that time. With
// --covariance, beside each of those poses the covariance a pf_pose
// subscriber holds at that scan: pf_node publishes the estimate at each filter
// update (and on a re-initialisation), so between updates it is the last
// update's.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <deque>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pf_localization/core/map/map_loader.h"
#include "pf_localization/ros/diagnostics/update_timing.h"
#include "pf_localization/ros/input/bag_contents.h"
#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/localizer/scan_localizer.h"
#include "pf_localization/ros/params/localizer_config.h"

namespace {

constexpr char kUsage[] =
    "usage: pf_bag_runner --bag BAG --map MAP.yaml --out TRAJ.tum\n"
    "         [--initial-pose X Y YAW]   start here (global localization without it)\n"
    "         [--particles N]            maximum particle count\n"
    "         [--max-beams B] [--seed S] [--params FILE.yaml]\n"
    "         [--scan-topic /scan]...        once per lidar: several are fused\n"
    "         [--cloud-topic /points]...     once per 3D lidar or depth camera (PointCloud2)\n"
    "         [--odom-topic /odom]\n"
    "         [--log UPDATES.csv]        one line per filter update\n"
    "         [--particles-out P.csv]    every particle of every update in the first 30 s\n"
    "         [--covariance COV.csv]     t,xx,xy,yy,yawyaw,xyaw,yyaw: pf_pose's covariance\n"
    "                                    at each pose of the trajectory (same stamps)\n"
    "         [--hypotheses HYP.csv]     t,rank,x,y,yaw,weight,std_x,std_y,cov_xy: pf_hypotheses,\n"
    "                                    one line per hypothesis per filter update\n"
    "         [--changes CHANGES.yaml]   where the world no longer matches the map, as learned\n"
    "                                    by the end (pf_map_changes): a map_server pair, pixel\n"
    "                                    0 added, 205 removed, 254 seen as mapped, 128 unseen\n"
    "         [--pace RATE]              the scans at the bag's own pace times RATE, on the\n"
    "                                    wall clock (pf_node's rhythm on a replay at RATE), not\n"
    "                                    as fast as possible: for CPU figures comparable to it\n"
    "         [--quiet]                  no progress bar\n";

// How long (bag time) a scan may wait for its odometry before it is used anyway.
constexpr double kMaxTfWait = 1.0;
// The particle dump covers the start of the run, where convergence happens.
constexpr double kParticleDumpSeconds = 30.0;

struct Options {
  std::string bag, map, out, params, log, particles_out, covariance, hypotheses, changes;
  std::vector<std::string> scan_topics;   // empty: /scan
  std::vector<std::string> cloud_topics;  // PointCloud2 topics, sensors after the scan topics
  std::string odom_topic = "/odom";
  std::optional<pf::Pose2> initial_pose;
  int particles = 0, max_beams = 0;
  long seed = -1;
  double pace = 0.0;  // 0: as fast as possible
  bool quiet = false;
};

[[noreturn]] void fail(const std::string& message, int code = 2) {
  std::cerr << "pf_bag_runner: " << message << "\n";
  std::exit(code);
}

double number(const std::string& flag, const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v)) {
    fail(flag + " expects a number, got '" + text + "'\n" + kUsage);
  }
  return v;
}

Options parse(int argc, char** argv) {
  Options o;

  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](int k = 1) -> const char* {
      if (i + k >= argc) fail(a + " needs " + std::to_string(k) + " value(s)\n" + kUsage);
      return argv[i + k];
    };
    if (a == "--bag")
      o.bag = value(), ++i;
    else if (a == "--map")
      o.map = value(), ++i;
    else if (a == "--out")
      o.out = value(), ++i;
    else if (a == "--params")
      o.params = value(), ++i;
    else if (a == "--log")
      o.log = value(), ++i;
    else if (a == "--particles-out")
      o.particles_out = value(), ++i;
    else if (a == "--covariance")
      o.covariance = value(), ++i;
    else if (a == "--hypotheses")
      o.hypotheses = value(), ++i;
    else if (a == "--changes")
      o.changes = value(), ++i;
    else if (a == "--scan-topic")
      o.scan_topics.push_back(value()), ++i;
    else if (a == "--cloud-topic")
      o.cloud_topics.push_back(value()), ++i;
    else if (a == "--odom-topic")
      o.odom_topic = value(), ++i;
    else if (a == "--particles")
      o.particles = static_cast<int>(number(a, value())), ++i;
    else if (a == "--max-beams")
      o.max_beams = static_cast<int>(number(a, value())), ++i;
    else if (a == "--seed")
      o.seed = static_cast<long>(number(a, value())), ++i;
    else if (a == "--initial-pose") {
      o.initial_pose = pf::Pose2{number(a, value(1)), number(a, value(2)), number(a, value(3))};
      i += 3;
    } else if (a == "--pace") {
      o.pace = number(a, value()), ++i;
      if (o.pace <= 0.0) fail("--pace expects a rate above 0\n" + std::string(kUsage));
    } else if (a == "--quiet")
      o.quiet = true;
    else if (a == "-h" || a == "--help")
      std::cout << kUsage, std::exit(0);
    else
      fail("unknown argument '" + a + "'\n" + kUsage);
  }
  if (o.bag.empty() || o.map.empty() || o.out.empty())
    fail(std::string("--bag, --map and --out are required\n") + kUsage);
  if (o.scan_topics.empty() && o.cloud_topics.empty()) o.scan_topics.push_back("/scan");
  return o;
}

// A topic list as the parameters take it: separated by spaces.
std::string joined(const std::vector<std::string>& topics) {
  std::string out;
  for (const std::string& t : topics) out += (out.empty() ? "" : " ") + t;
  return out;
}

pf_ros::LocalizerConfig makeConfig(const Options& o) {
  try {
    pf_ros::LocalizerConfig c;
    if (!o.params.empty()) c = pf_ros::readConfig(*pf_ros::yamlParamSource(o.params));
    if (o.initial_pose) c.initial_pose = o.initial_pose;
    if (o.particles > 0) {
      c.filter.kld.max_particles = o.particles;
      c.filter.kld.min_particles = std::min(c.filter.kld.min_particles, o.particles);
    } else if (o.particles < 0) {
      throw std::invalid_argument("invalid --particles: must be >= 1");
    }
    if (o.max_beams != 0) c.filter.sensor.max_beams = o.max_beams;
    if (o.seed >= 0) c.filter.seed = static_cast<uint64_t>(o.seed);
    // The sensors by their topics, as pf_node has them (sensorTopics()).
    c.scan_topics = joined(o.scan_topics);
    c.cloud_topics = joined(o.cloud_topics);
    pf::validate(c.filter);
    return c;
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

double clockSeconds(clockid_t clock) {
  timespec ts;
  clock_gettime(clock, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
double threadCpuSeconds() { return clockSeconds(CLOCK_THREAD_CPUTIME_ID); }

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}
  void show(double fraction, double t) {
    if (!enabled_) return;
    const int percent = static_cast<int>(fraction * 100.0);
    if (percent == last_) return;
    last_ = percent;
    const int filled = percent * 40 / 100;
    std::cerr << "\r[" << std::string(filled, '#') << std::string(40 - filled, ' ') << "] "
              << std::setw(3) << percent << "%  t=" << std::fixed << std::setprecision(1) << t
              << " s" << std::flush;
  }
  void done() {
    if (enabled_) std::cerr << "\n";
  }

 private:
  bool enabled_;
  int last_ = -1;
};

pf_ros::BagTopics bagTopics(const Options& opt) {
  return pf_ros::BagTopics{opt.scan_topics, opt.cloud_topics, opt.odom_topic};
}

// Opens the bag, which must have every sensor's topic, of its type.
void openBag(const Options& opt, rosbag::Bag* bag) {
  try {
    bag->open(opt.bag, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    fail(opt.bag + ": cannot read the bag: " + e.what());
  }
  try {
    pf_ros::checkSensorTopics(*bag, bagTopics(opt));
  } catch (const pf_ros::BagContentError& e) {
    fail(opt.bag + ": " + e.what());
  }
}

void loadMap(const Options& opt, pf_ros::ScanLocalizer* localizer) {
  try {
    // Moved into the filter: no message, no second copy of the map.
    const std::string error = localizer->setMap(pf::loadMap(opt.map));
    if (!error.empty()) fail(opt.map + ": " + error);
  } catch (const pf::MapLoadError& e) {
    fail(e.what());
  }
}

// The files a run writes: the trajectory, and the optional update log,
// particle dump, covariance and hypotheses (closed streams when not asked for).
struct Outputs {
  std::ofstream out, log, dump, cov, hypotheses;
};

void openOutputs(const Options& opt, Outputs* o) {
  o->out.open(opt.out);
  if (!o->out) fail(opt.out + ": cannot write");
  o->out << std::fixed << std::setprecision(6);
  if (!opt.log.empty()) {
    o->log.open(opt.log);
    if (!o->log) fail(opt.log + ": cannot write");
    o->log << "t,particles,ess,cpu_ms,mean_beam_likelihood,std_x,std_y,std_yaw,updated,injected,"
              "tempering,hit_fraction,rivals,state,refined,refine_translation,refine_rotation,"
              "refine_rms,refine_matched,fault_fraction,search_sigma,look_alikes,"
              "look_alikes_better,beams_changed,map_changed_share,missing\n";
  }
  if (!opt.particles_out.empty()) {
    o->dump.open(opt.particles_out);
    if (!o->dump) fail(opt.particles_out + ": cannot write");
    o->dump << "t,x,y,yaw\n" << std::setprecision(4) << std::fixed;
  }
  if (!opt.covariance.empty()) {
    o->cov.open(opt.covariance);
    if (!o->cov) fail(opt.covariance + ": cannot write");
    o->cov << "t,xx,xy,yy,yawyaw,xyaw,yyaw\n";
  }
  if (!opt.hypotheses.empty()) {
    o->hypotheses.open(opt.hypotheses);
    if (!o->hypotheses) fail(opt.hypotheses + ": cannot write");
    o->hypotheses << "t,rank,x,y,yaw,weight,std_x,std_y,cov_xy\n"
                  << std::fixed << std::setprecision(6);
  }
}

// What the summary reports.
struct RunCounts {
  std::size_t scans = 0, written = 0, updates = 0;
  double cpu_total = 0.0;
  // CPU time of every update, for the percentiles in the summary.
  pf_ros::RollingPercentiles update_cpu{std::numeric_limits<std::size_t>::max()};
  std::map<std::string, int> errors;  // scans not used, by reason
};

// The replay: feeds the bag's tf and odometry to tf2 and each scan, once its
// odometry has arrived, to the localizer, writing what each one gives.
class Replay {
 public:
  Replay(const Options& opt, const pf_ros::LocalizerConfig& config, bool odom_on_tf,
         tf2::BufferCore* tf, pf_ros::ScanLocalizer* localizer, Outputs* outputs)
      : opt_(opt),
        config_(config),
        sensors_(pf_ros::sensorTopics(config)),
        odom_on_tf_(odom_on_tf),
        tf_(*tf),
        localizer_(*localizer),
        outputs_(*outputs) {}

  void run(const rosbag::Bag& bag);
  const RunCounts& counts() const { return counts_; }
  // What the replay reads: the scans, the odometry and tf.
  std::vector<std::string> topics() const {
    std::vector<std::string> t = sensors_;
    t.insert(t.end(), {opt_.odom_topic, "/tf", "/tf_static"});
    return t;
  }

 private:
  void handle(const rosbag::MessageInstance& m);
  // A scan or a cloud waiting for its odometry, with its sensor: the index of
  // its --scan-topic, or of its --cloud-topic after those.
  struct Pending {
    sensor_msgs::LaserScan::ConstPtr scan;
    sensor_msgs::PointCloud2::ConstPtr cloud;
    std::size_t sensor;
    const std_msgs::Header& header() const { return scan ? scan->header : cloud->header; }
  };
  void process(const Pending& pending);
  void logUpdate(double t, const pf_ros::ScanResult& r, double cpu);
  std::string missingNames(double t) const;
  void dumpParticles(double t);
  void writeHypotheses(double t);
  void writeCovariance(double t);
  // A sensor that went missing or came back: one line on stderr, as pf_node's
  // diagnostics name it.
  void reportSensors(double t);

  const Options& opt_;
  const pf_ros::LocalizerConfig& config_;
  // Every sensor's topic: a sensor's index is its place (--scan-topic, then --cloud-topic).
  const std::vector<std::string> sensors_;
  const bool odom_on_tf_;
  tf2::BufferCore& tf_;
  pf_ros::ScanLocalizer& localizer_;
  Outputs& outputs_;
  // The scans waiting for their odometry, with their sensor (--scan-topic's index).
  std::deque<Pending> pending_;
  // What pf_node last published on pf_pose (it publishes at each update).
  std::optional<geometry_msgs::PoseWithCovarianceStamped> published_;
  RunCounts counts_;
  double first_stamp_ = -1.0;
  std::string missing_;  // the sensors missing as last reported
};

void Replay::run(const rosbag::Bag& bag) {
  rosbag::View view(bag, rosbag::TopicQuery(topics()));
  const double t_begin = view.getBeginTime().toSec(), t_end = view.getEndTime().toSec();
  ProgressBar progress(!opt_.quiet);
  const auto wall_begin = std::chrono::steady_clock::now();
  // pf_node publishes the estimate once it has the map, as the filter starts.
  if (outputs_.cov) published_ = localizer_.estimate(ros::Time(t_begin));
  try {
    for (const rosbag::MessageInstance& m : view) {
      const double now = m.getTime().toSec();
      // An update that runs once a scan period finds the CPU's caches cold:
      // on a virtual machine it costs two to three times one run back to back.
      if (opt_.pace > 0.0) {
        std::this_thread::sleep_until(wall_begin +
                                      std::chrono::duration<double>((now - t_begin) / opt_.pace));
      }
      handle(m);
      // A scan is used once odometry reaches its stamp, as pf_node's tf
      // message filter would, or when it has waited too long.
      while (!pending_.empty()) {
        const std_msgs::Header& h = pending_.front().header();
        const bool ready = tf_.canTransform(config_.odom_frame, config_.base_frame, h.stamp) &&
                           tf_.canTransform(config_.base_frame, h.frame_id, ros::Time(0));
        if (!ready && now - h.stamp.toSec() < kMaxTfWait) {
          break;
        }
        process(pending_.front());
        pending_.pop_front();
      }
      progress.show((now - t_begin) / std::max(1e-9, t_end - t_begin), now - t_begin);
    }
  } catch (const rosbag::BagException& e) {
    fail(opt_.bag + ": error while reading: " + e.what());
  }
  for (const Pending& p : pending_) process(p);
  progress.done();
}

// One message: tf and odometry into tf2, a scan into the queue.
void Replay::handle(const rosbag::MessageInstance& m) {
  if (m.getTopic() == "/tf" || m.getTopic() == "/tf_static") {
    const bool is_static = m.getTopic() == "/tf_static";
    if (const auto msg = m.instantiate<tf2_msgs::TFMessage>()) {
      for (const auto& t : msg->transforms) tf_.setTransform(t, "bag", is_static);
    }
  } else if (m.getTopic() == opt_.odom_topic) {
    const auto odom = m.instantiate<nav_msgs::Odometry>();
    if (odom && !odom_on_tf_) tf_.setTransform(pf_ros::odometryToTransform(*odom), "odom_topic");
  } else {
    const auto topic = std::find(sensors_.begin(), sensors_.end(), m.getTopic());
    if (topic == sensors_.end()) return;
    const auto sensor = static_cast<std::size_t>(topic - sensors_.begin());
    Pending p{nullptr, nullptr, sensor};
    if (sensor < opt_.scan_topics.size()) {
      p.scan = m.instantiate<sensor_msgs::LaserScan>();
    } else {
      p.cloud = m.instantiate<sensor_msgs::PointCloud2>();
    }
    if (!p.scan && !p.cloud) return;  // another type on the topic
    ++counts_.scans;
    pending_.push_back(p);
  }
}

void Replay::process(const Pending& pending) {
  const double cpu0 = threadCpuSeconds();
  const pf_ros::ScanResult r = pending.scan
                                   ? localizer_.processScan(*pending.scan, pending.sensor)
                                   : localizer_.processCloud(*pending.cloud, pending.sensor);
  const double cpu = threadCpuSeconds() - cpu0;
  counts_.cpu_total += cpu;
  const std_msgs::Header& header = pending.header();
  const double t = header.stamp.toSec();
  if (first_stamp_ < 0) first_stamp_ = t;
  if (r.error != pf_ros::ScanError::kNone) {
    if (counts_.errors[pf_ros::toString(r.error)]++ == 0)
      std::cerr << "\npf_bag_runner: warning: " << pf_ros::errorMessage(r) << "\n";
    return;
  }
  reportSensors(t);
  if (r.report.updated) {
    if (outputs_.cov) published_ = localizer_.estimate(header.stamp);
    ++counts_.updates;
    counts_.update_cpu.add(cpu);
    if (outputs_.log) logUpdate(t, r, cpu);
    if (outputs_.dump && t - first_stamp_ <= kParticleDumpSeconds) dumpParticles(t);
    if (outputs_.hypotheses) writeHypotheses(t);
  }
  // The pose a tf user would get: the newest map -> odom composed with the
  // odometry at the scan's stamp.
  const auto m2o = localizer_.filter().mapToOdom();
  if (!m2o || !r.odom) return;
  const pf::Pose2 pose = pf::compose(*m2o, *r.odom);
  outputs_.out << t << " " << pose.x << " " << pose.y << " 0 0 0 " << std::sin(pose.yaw / 2) << " "
               << std::cos(pose.yaw / 2) << "\n";
  if (outputs_.cov) writeCovariance(t);
  ++counts_.written;
}

// The sensors missing at `t`, by name, separated by spaces (the log's column).
std::string Replay::missingNames(double t) const {
  std::string names;
  for (const pf::SensorStatus& s : localizer_.sensorHealth().status(t)) {
    if (s.state != pf::SensorState::kSilent && s.state != pf::SensorState::kBlocked) continue;
    names += (names.empty() ? "" : " ") + s.name;
  }
  return names;
}

void Replay::reportSensors(double t) {
  const std::string missing = localizer_.sensorHealth().missing(t);
  if (missing == missing_) return;
  std::cerr << "\npf_bag_runner: t=" << std::fixed << std::setprecision(1) << t - first_stamp_
            << " s: " << (missing.empty() ? "every sensor is back" : "missing: " + missing) << "\n";
  std::cerr.unsetf(std::ios::floatfield);
  missing_ = missing;
}

// One line of the covariance file: the published message's x, y, yaw terms.
void Replay::writeCovariance(double t) {
  outputs_.cov << std::fixed << std::setprecision(6) << t;
  if (!published_) {
    outputs_.cov << ",nan,nan,nan,nan,nan,nan\n";
    return;
  }
  const Eigen::Matrix3d c = pf_ros::fromRosCovariance(published_->pose.covariance);
  outputs_.cov << std::scientific << std::setprecision(9);
  for (const double v : {c(0, 0), c(0, 1), c(1, 1), c(2, 2), c(0, 2), c(1, 2)}) {
    outputs_.cov << "," << v;
  }
  outputs_.cov << "\n";
}

// One line of the update log (the columns of openOutputs' header).
void Replay::logUpdate(double t, const pf_ros::ScanResult& r, double cpu) {
  const auto& est = localizer_.filter().estimate();
  const pf::Confidence& conf = localizer_.filter().confidence();
  outputs_.log << std::fixed << std::setprecision(6) << t << "," << r.report.particles << ","
               << std::setprecision(1) << r.report.ess << "," << std::setprecision(3) << cpu * 1e3
               << "," << std::setprecision(6) << r.report.mean_beam_likelihood << ","
               << std::sqrt(est.covariance(0, 0)) << "," << std::sqrt(est.covariance(1, 1)) << ","
               << std::sqrt(est.covariance(2, 2)) << ",1," << r.report.injected << ","
               << r.report.tempering << "," << conf.hit_fraction << "," << conf.rivals << ","
               << pf::toString(conf.state) << "," << r.report.refinement.accepted << ","
               << r.report.refinement.translation << "," << r.report.refinement.rotation << ","
               << r.report.refinement.rms_distance << "," << r.report.refinement.matched_beams
               << "," << r.report.fault_fraction << "," << r.report.search_sigma << ","
               << r.report.look_alikes << "," << r.report.look_alikes_better << ","
               << r.report.beams_changed << "," << r.report.map_changed_share << ","
               << missingNames(t) << "\n";
}

void Replay::dumpParticles(double t) {
  const pf::ParticleSet& p = localizer_.filter().particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    outputs_.dump << t << "," << p.x[i] << "," << p.y[i] << "," << p.yaw[i] << "\n";
  }
}

// What pf_node publishes on pf_hypotheses after this update, one line per
// hypothesis, heaviest (rank 1) first.
void Replay::writeHypotheses(double t) {
  const pf::Hypotheses h = localizer_.filter().hypotheses();
  for (std::size_t k = 0; k < h.listed.size(); ++k) {
    const pf::Hypothesis& a = h.listed[k];
    outputs_.hypotheses << t << "," << k + 1 << "," << a.pose.x << "," << a.pose.y << ","
                        << a.pose.yaw << "," << a.weight << "," << std::sqrt(a.covariance(0, 0))
                        << "," << std::sqrt(a.covariance(1, 1)) << "," << a.covariance(0, 1)
                        << "\n";
  }
}

// The summary on stderr; exits with an error when no scan was found or no
// pose written.
void summarize(const Options& opt, const RunCounts& c) {
  std::cerr << "pf_bag_runner: " << c.scans << " scans, " << c.updates << " filter updates, "
            << c.written << " poses written to " << opt.out << "; CPU " << std::setprecision(3)
            << c.cpu_total << " s (" << (c.updates ? 1e3 * c.cpu_total / c.updates : 0.0)
            << " ms per update)\n";
  if (c.updates > 0) {
    std::cerr << "pf_bag_runner: CPU per update: p50 " << 1e3 * c.update_cpu.percentile(0.5)
              << " ms, p95 " << 1e3 * c.update_cpu.percentile(0.95) << " ms, max "
              << 1e3 * c.update_cpu.max() << " ms\n";
  }
  for (const auto& e : c.errors) {
    std::cerr << "pf_bag_runner: " << e.second << " scans not used: " << e.first << "\n";
  }
  if (c.scans == 0) fail(opt.bag + ": no scans or clouds on the topics asked for");
  if (c.written == 0) fail("no pose could be estimated (see the warnings above)", 3);
}

// The map's changes learned over the run: a summary line, and the layer
// itself with --changes.
void writeChanges(const Options& opt, const pf_ros::ScanLocalizer& localizer) {
  const pf::MapChangeLayer* layer = localizer.mapChanges();
  if (layer == nullptr) return;
  const pf::MapChangeLayer::Summary s = layer->summary();
  std::cerr << "pf_bag_runner: map changes: " << s.seen << " cells seen from " << layer->scans()
            << " updates, " << s.added << " added, " << s.removed << " removed ("
            << std::setprecision(2) << std::fixed << 100.0 * s.changedShare() << " %)\n";
  if (opt.changes.empty()) return;
  try {
    pf::saveImage(*localizer.filter().map(), layer->pixels(), opt.changes);
  } catch (const std::exception& e) {
    fail(opt.changes + ": " + e.what(), 3);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const pf_ros::LocalizerConfig config = makeConfig(opt);
  rosbag::Bag bag;
  openBag(opt, &bag);
  const bool odom_on_tf = pf_ros::odometryOnTf(bag, config);
  try {
    pf_ros::checkFrames(bag, bagTopics(opt), config, odom_on_tf);
  } catch (const pf_ros::BagContentError& e) {
    fail(opt.bag + ": " + e.what());
  }
  tf2::BufferCore tf(ros::Duration(600.0));
  pf_ros::ScanLocalizer localizer(config, &tf);
  // The likelihood tables for the scans are built with the map, not by the first update.
  for (double r : pf_ros::firstScanRanges(bag, bagTopics(opt)))
    localizer.filter().expectScanRange(r);
  // The process's CPU: the map is built on every thread the filter may use.
  const double setup_cpu0 = clockSeconds(CLOCK_PROCESS_CPUTIME_ID);
  const double setup_wall0 = clockSeconds(CLOCK_MONOTONIC);
  loadMap(opt, &localizer);
  const double setup_cpu = clockSeconds(CLOCK_PROCESS_CPUTIME_ID) - setup_cpu0;
  const double setup_wall = clockSeconds(CLOCK_MONOTONIC) - setup_wall0;
  Outputs outputs;
  openOutputs(opt, &outputs);
  Replay replay(opt, config, odom_on_tf, &tf, &localizer, &outputs);
  replay.run(bag);
  summarize(opt, replay.counts());
  std::cerr << "pf_bag_runner: map set-up CPU " << std::setprecision(3) << std::fixed << setup_cpu
            << " s\npf_bag_runner: map set-up wall " << setup_wall << " s\n";
  writeChanges(opt, localizer);
  return 0;
}
