#include "pf_localization/ros/params/localizer_config.h"

#include <ros/console.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "pf_localization/core/util/parameter_table.h"
#include "pf_localization/ros/params/amcl_params.h"

namespace pf_ros {
namespace {

template <typename T>
std::string show(const T& value) {
  if constexpr (std::is_same_v<T, double>) {
    return pf::formatNumber(value);
  } else {
    std::ostringstream s;
    s << std::boolalpha << value;
    return s.str();
  }
}

// Whether our `name` set to `ours` and its amcl alias set to `amcls` mean the same.
template <typename T>
bool agree(const std::string& name, const T& ours, const T& amcls) {
  if constexpr (std::is_same_v<T, double>) {
    if (name == "kld_confidence") return std::fabs(kldConfidenceFromZ(amcls) - ours) < 1e-9;
  }
  return ours == amcls;
}

double nan() { return std::numeric_limits<double>::quiet_NaN(); }

// initial_pose_x / _y / _a: the optional pose, one coordinate at a time.
pf::Parameter<LocalizerConfig> initialPoseRow(double pf::Pose2::*coordinate, pf::ParamInfo info) {
  return pf::computed<LocalizerConfig, double>(
      [coordinate](const LocalizerConfig& c) {
        return c.initial_pose ? (*c.initial_pose).*coordinate
                              : (coordinate == &pf::Pose2::yaw ? 0.0 : nan());
      },
      [coordinate](LocalizerConfig& c, const double& v) {
        if (!c.initial_pose) c.initial_pose = pf::Pose2{nan(), nan(), 0.0};
        (*c.initial_pose).*coordinate = v;
      },
      std::move(info));
}

// initial_cov_xx / _yy / _aa: the diagonal of the initial covariance.
pf::Parameter<LocalizerConfig> initialCovRow(int i, pf::ParamInfo info) {
  return pf::computed<LocalizerConfig, double>(
      [i](const LocalizerConfig& c) { return c.initial_cov(i, i); },
      [i](LocalizerConfig& c, const double& v) { c.initial_cov(i, i) = v; }, std::move(info));
}

using C = LocalizerConfig;
using I = pf::ParamInfo;
using pf::Range;

pf::ParameterTable<C> frameParameters() {
  return {pf::member(&C::global_frame,
                     I("global_frame", "", "frame of the map and the published estimates")
                         .amclAlias("global_frame_id")),
          pf::member(&C::odom_frame,
                     I("odom_frame", "", "frame of the wheel odometry").amclAlias("odom_frame_id")),
          pf::member(&C::base_frame,
                     I("base_frame", "", "the robot's body frame (odom -> it is odometry)")
                         .amclAlias("base_frame_id"))};
}

pf::ParameterTable<C> outputParameters() {
  return {
      pf::member(&C::tf_broadcast, I("tf_broadcast", "", "publish map -> odom on tf").amcl()),
      pf::member(&C::transform_tolerance,
                 I("transform_tolerance", "s",
                   "map -> odom is stamped this far ahead, so tf users never extrapolate")
                     .in(Range::atLeast(0))
                     .amcl()
                     .live(0, 10)),
      pf::member(&C::gui_publish_rate,
                 I("gui_publish_rate", "Hz", "particlecloud messages per second at most")
                     .in(Range::any())
                     .withNote("<= 0: one per update")
                     .amcl()
                     .live(-1, 100)),
      pf::member(&C::save_pose_rate,
                 I("save_pose_rate", "Hz",
                   "the pose is saved to ~initial_pose_* this often, for a restarted node")
                     .in(Range::any())
                     .withNote("<= 0: never")
                     .amcl()),
      pf::member(&C::map_changes_file,
                 I("map_changes_file", "path",
                   "pf_map_changes' layer is saved to this file with the pose, and restored on "
                   "the same map; empty: $ROS_HOME/NODE.map_changes (~/.ros/pf_node.map_changes)")
                     .unsetMeans("the default")),
      pf::member(&C::max_update_time,
                 I("max_update_time", "s",
                   "cap the particle count so that an update takes this long at p95")
                     .in(Range{-Range::kInf, 10.0})
                     .withNote("<= 0: no cap")
                     .live(0, 10)),
      pf::member(&C::first_map_only,
                 I("first_map_only", "", "ignore maps after the first on the map topic").amcl()),
      // Read by readConfig itself: false sets first_map_only, with a note.
      pf::computed<C, bool>(
          [](const C&) { return true; }, [](C&, const bool&) {},
          I("use_map_topic", "", "false: keep the first map, as amcl does without the topic")
              .amcl()),
      pf::member(&C::floors_file,
                 I("floors_file", "path",
                   "a building's floors (name and map of each): the maps come from it, not the "
                   "map topic, and change_floor moves between them")
                     .unsetMeans("one map, from the map topic or set_map"))};
}

pf::ParameterTable<C> initialPoseParameters() {
  return {
      initialPoseRow(&pf::Pose2::x, I("initial_pose_x", "m", "initial x in global_frame")
                                        .in(Range::any())
                                        .unsetMeans("global localization")
                                        .amcl()),
      initialPoseRow(&pf::Pose2::y, I("initial_pose_y", "m", "initial y in global_frame")
                                        .in(Range::any())
                                        .unsetMeans("global localization")
                                        .amcl()),
      initialPoseRow(&pf::Pose2::yaw,
                     I("initial_pose_a", "rad", "initial yaw").in(Range::any()).amcl()),
      initialCovRow(
          0, I("initial_cov_xx", "m^2", "variance of the initial x").in(Range::atLeast(0)).amcl()),
      initialCovRow(
          1, I("initial_cov_yy", "m^2", "variance of the initial y").in(Range::atLeast(0)).amcl()),
      initialCovRow(2, I("initial_cov_aa", "rad^2", "variance of the initial yaw")
                           .in(Range::atLeast(0))
                           .amcl())};
}

pf::ParameterTable<C> scanParameters() {
  return {
      pf::member(&C::deskew_scans,
                 I("deskew_scans", "",
                   "place each beam from where the laser was when it took it (time_increment)")),
      pf::member(&C::scan_stamp,
                 I("scan_stamp", "", "which beam a scan's stamp is the time of, for deskew_scans")
                     .oneOf({"first_beam", "last_beam"})),
      pf::member(&C::scan_topics,
                 I("scan_topics", "topic names",
                   "the lidars' scan topics, separated by spaces: several are weighed together, "
                   "each scan from where its lidar was")
                     .withNote("e.g. \"scan_front scan_rear\"; one: amcl's scan")
                     .unsetMeans("no lidar: cloud_topics alone")),
      pf::member(&C::cloud_topics,
                 I("cloud_topics", "topic names",
                   "3D lidars' and depth cameras' PointCloud2 topics, separated by spaces: "
                   "each cut to the cloud height band, reduced to a scan and weighed with the "
                   "lidars")
                     .withNote("e.g. \"points\"")
                     .unsetMeans("none")),
      pf::member(&C::scan_weights,
                 I("scan_weights", "weights in (0, 1]",
                   "how much each sensor counts, scan_topics then cloud_topics, separated by "
                   "spaces: below 1 for a sensor known to be worse")
                     .withNote("the last one for the topics after it; e.g. \"1 0.5\""))};
}

// The words of `text` between spaces, commas and tabs.
std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::string word;
  for (const char c : text + " ") {
    if (c == ' ' || c == ',' || c == '\t') {
      if (!word.empty()) out.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  return out;
}

}  // namespace

std::vector<std::string> scanTopics(const LocalizerConfig& config) {
  return words(config.scan_topics);
}

std::vector<std::string> cloudTopics(const LocalizerConfig& config) {
  return words(config.cloud_topics);
}

std::vector<std::string> sensorTopics(const LocalizerConfig& config) {
  std::vector<std::string> topics = scanTopics(config);
  for (std::string& t : cloudTopics(config)) topics.push_back(std::move(t));
  return topics;
}

std::vector<double> scanWeights(const LocalizerConfig& config) {
  std::vector<double> weights;
  for (const std::string& w : words(config.scan_weights)) {
    char* end = nullptr;
    const double v = std::strtod(w.c_str(), &end);
    if (end == w.c_str() || *end != '\0' || !(v > 0.0 && v <= 1.0)) {
      throw std::invalid_argument(pf::invalidParameterMessage(
          "scan_weights", "\"" + config.scan_weights + "\"", "numbers in (0, 1], one per topic"));
    }
    weights.push_back(v);
  }
  if (weights.empty()) {
    throw std::invalid_argument(pf::invalidParameterMessage(
        "scan_weights", "\"" + config.scan_weights + "\"", "at least one number in (0, 1]"));
  }
  weights.resize(std::max(weights.size(), sensorTopics(config).size()), weights.back());
  return weights;
}

namespace {

// The rows of LocalizerConfig's own members (the filter's are particleFilterParameters()).
const pf::ParameterTable<C>& ownParameters() {
  static const pf::ParameterTable<C> table = [] {
    pf::ParameterTable<C> t;
    pf::append(&t, frameParameters(), "frames");
    pf::append(&t, outputParameters(), "output");
    pf::append(&t, initialPoseParameters(), "initial_pose");
    pf::append(&t, scanParameters(), "scan");
    // The cloud's height band; its bins and range limits are the reducer's own.
    pf::ParameterTable<C> band;
    for (const auto& p : pf::nested(&C::cloud, pf::cloudScanParameters())) {
      if (p.info.name == "cloud_min_height" || p.info.name == "cloud_max_height") band.push_back(p);
    }
    pf::append(&t, band, "scan");
    return t;
  }();
  return table;
}

// What the sources' values mean once all are read: frames without tf's
// leading slash, amcl's -1 for "the scan's own limit", an initial pose only
// when both x and y are given.
void finishReading(LocalizerConfig* c) {
  // tf2 refuses frame ids with a leading slash, which tf (and so many amcl
  // configurations) used; amcl strips it too.
  for (std::string* frame : {&c->global_frame, &c->odom_frame, &c->base_frame}) {
    if (!frame->empty() && frame->front() == '/') frame->erase(0, 1);
  }
  c->filter.sensor.range_min = std::max(c->filter.sensor.range_min, 0.0);
  c->filter.sensor.range_max = std::max(c->filter.sensor.range_max, 0.0);
  if (c->initial_pose &&
      !(std::isfinite(c->initial_pose->x) && std::isfinite(c->initial_pose->y))) {
    c->initial_pose.reset();
  }
}

// Names that were parameters until they became named constants of the
// filter's algorithms; a configuration that sets one is told so.
// Parameters under a new name: a configuration that still sets the old one
// is told which (nullptr: not renamed).
const char* renamedTo(const std::string& name) {
  // The whole update runs on several threads now, not only the scoring.
  if (name == "sensor_threads") return "threads";
  return nullptr;
}

bool isRetired(const std::string& name) {
  static const std::set<std::string> names = {"kld_bin_xy",
                                              "kld_bin_yaw",
                                              "update_fit_drop",
                                              "update_fit_distance",
                                              "odom_jump_limit",
                                              "resample_ess_fraction",
                                              "tempering_ess_fraction",
                                              "tempering_ess_fraction_uncertain",
                                              "seed",
                                              "cluster_xy",
                                              "cluster_yaw",
                                              "cluster_join_weight_ratio",
                                              "recovery_trigger_ratio",
                                              "recovery_patience",
                                              "recovery_patience_localized",
                                              "recovery_lost_share",
                                              "recovery_kidnap_prior",
                                              "recovery_expansion_ratio",
                                              "recovery_expansion_std_xy",
                                              "recovery_expansion_std_yaw",
                                              "refine_max_beams",
                                              "refine_max_iterations",
                                              "refine_outlier_distance",
                                              "refine_cauchy_scale",
                                              "refine_wall_offset",
                                              "refine_min_matched_fraction",
                                              "refine_min_matched_beams",
                                              "refine_max_translation",
                                              "refine_max_rotation",
                                              "refine_min_beam_std",
                                              "refine_degeneracy_ratio",
                                              "refine_beam_std",
                                              "refine_convergence",
                                              "confidence_hit_distance",
                                              "confidence_lost_hit_fraction",
                                              "confidence_localized_hit_fraction",
                                              "confidence_localized_std_xy",
                                              "confidence_localized_std_yaw",
                                              "confidence_rival_weight_ratio",
                                              "confidence_jump_distance",
                                              "confidence_jump_yaw",
                                              "confidence_settle_updates",
                                              "odom_fault_fraction",
                                              "odom_fault_fraction_max",
                                              "odom_fault_suspect_fraction",
                                              "odom_fault_margin",
                                              "tf_publish_rate",
                                              "cloud_max_poses"};
  return names.count(name) > 0;
}

// A value found under amcl's name, in our units. amcl's kld_z is the normal
// quantile of our kld_confidence (the one alias that is not a plain rename).
template <typename T>
T fromAlias(const pf::ParamInfo& info, const std::string& found, const T& value) {
  if constexpr (std::is_same_v<T, double>) {
    if (found == "kld_z" && found != info.name) {
      const double p = kldConfidenceFromZ(value);
      if (!(std::isfinite(value) && p > 0.0 && p < 1.0)) {
        throw std::invalid_argument(pf::invalidParameterMessage(
            "kld_z", pf::formatNumber(value),
            "a finite normal quantile between -8 and 8 (amcl's default: 0.99)"));
      }
      return p;
    }
  }
  return value;
}

// Looks each setting up under our name and amcl's, in the user's source
// before the defaults, and remembers every name asked for: whatever else the
// source holds is reported as unknown (a misspelt name would otherwise be
// silently ignored, the classic amcl configuration bug).
class ParamReader {
 public:
  ParamReader(const ParamSource& source, const ParamSource* defaults, ConfigNotes* notes)
      : source_(source), defaults_(defaults), notes_(notes) {}

  /// Reads the row `p` into `config` when the sources have it. Returns the
  /// name it was found under; empty when absent (`config` untouched).
  std::string read(const pf::Parameter<LocalizerConfig>& p, LocalizerConfig* config) {
    return std::visit(
        [&](const auto& field) {
          auto value = field.get(*config);
          const std::string found = get(p.info, &value);
          if (!found.empty()) field.set(*config, fromAlias(p.info, found, value));
          return found;
        },
        p.field);
  }

  /// The name the value was found under; empty when absent (value untouched).
  template <typename T>
  std::string get(const pf::ParamInfo& info, T* value) {
    const std::string& name = info.name;
    known_.insert(name);
    std::optional<std::string> alias;
    if (info.amcl_kind == pf::Amcl::kAlias) alias = info.amcl_name;
    if (alias) known_.insert(*alias);
    for (const ParamSource* layer : {&source_, defaults_}) {
      if (layer == nullptr) continue;
      const bool ours = layer->get(name, value);
      T amcl_value{};
      if (alias && layer->get(*alias, &amcl_value)) {
        if (!ours) {
          *value = amcl_value;
          return *alias;
        }
        // pf_node's dynamic_reconfigure server writes both names, in
        // agreement, to the parameter server, where a respawned node finds them.
        if (!agree(name, *value, amcl_value)) {
          notes_->warnings.push_back("both " + name + " (" + show(*value) + ") and amcl's " +
                                     *alias + " (" + show(amcl_value) + ") are set: using " + name);
        }
      }
      if (ours) return name;
    }
    return "";
  }

  /// Marks `name` as known without reading it (state pf_node keeps on the
  /// parameter server, not a setting).
  void know(const std::string& name) { known_.insert(name); }

  /// Unknown names in the source, and the amcl parameters it sets that have no effect here.
  void reportLeftovers() {
    std::set<std::string> unused_amcl;
    for (const AmclOnlyParam& p : amclOnlyParams()) {
      if (known_.count(p.name)) continue;
      if (present(p.name)) {
        notes_->infos.push_back(std::string("amcl parameter ") + p.name + " ignored: " + p.why);
      }
      unused_amcl.insert(p.name);
    }
    std::string unknown, retired;
    for (const std::string& key : source_.keys()) {
      // "defaults" is the namespace launch/amcl_compatible.launch loads config/pf.yaml into.
      if (known_.count(key) || unused_amcl.count(key) || key == "defaults") continue;
      if (const char* now = renamedTo(key)) {
        notes_->warnings.push_back(key + " is now " + now +
                                   ", which splits the whole update: set " + now + "; " + key +
                                   " is ignored");
        continue;
      }
      std::string& list = isRetired(key) ? retired : unknown;
      list += (list.empty() ? "" : ", ") + key;
    }
    if (!retired.empty()) {
      notes_->infos.push_back(retired +
                              ": no longer parameters (constants of the filter's algorithms "
                              "(docs/design.md)): ignored");
    }
    if (!unknown.empty()) {
      notes_->warnings.push_back(
          "unknown parameters ignored (misspelt?): " + unknown +
          ". config/pf.yaml lists every parameter; README.md, \"Switching from amcl\", amcl's");
    }
  }

 private:
  // Whatever its type: a getter throws only for a name that is there.
  bool present(const std::string& name) const {
    std::string ignored;
    try {
      return source_.get(name, &ignored);
    } catch (const std::invalid_argument&) {
      return true;
    }
  }

  const ParamSource& source_;
  const ParamSource* defaults_;
  ConfigNotes* notes_;
  std::set<std::string> known_;
};

void logNotes(const ConfigNotes& notes) {
  for (const std::string& w : notes.warnings) ROS_WARN("%s", w.c_str());
  for (const std::string& i : notes.infos) ROS_INFO("%s", i.c_str());
}

}  // namespace

const pf::ParameterTable<LocalizerConfig>& localizerParameters() {
  static const pf::ParameterTable<LocalizerConfig> table = [] {
    const pf::ParameterTable<LocalizerConfig>& own = ownParameters();
    // The frames, the output and the initial pose, then the filter's, then the scan's.
    const auto scan =
        std::find_if(own.begin(), own.end(), [](const auto& p) { return p.info.group == "scan"; });
    pf::ParameterTable<LocalizerConfig> t(own.begin(), scan);
    for (const auto& p : pf::nested(&LocalizerConfig::filter, pf::particleFilterParameters())) {
      t.push_back(p);
    }
    t.insert(t.end(), scan, own.end());
    return t;
  }();
  return table;
}

LocalizerConfig readConfig(const ParamSource& source, const ParamSource* defaults,
                           ConfigNotes* notes) {
  ConfigNotes own_notes;
  ConfigNotes* out = notes != nullptr ? notes : &own_notes;
  ParamReader reader(source, defaults, out);
  LocalizerConfig c;
  bool use_map_topic_false = false;
  for (const pf::Parameter<LocalizerConfig>& p : localizerParameters()) {
    if (p.info.name == "use_map_topic") {
      bool use_map_topic = true;
      use_map_topic_false = !reader.get(p.info, &use_map_topic).empty() && !use_map_topic;
      continue;
    }
    reader.read(p, &c);
  }
  reader.know(kSavedPoseMapParam);
  finishReading(&c);
  if (use_map_topic_false && !c.first_map_only) {
    // amcl then asks map_server's static_map service once and never updates
    // its map. map_server publishes the same map latched on the map topic, so
    // taking the first map from there and keeping it behaves the same.
    c.first_map_only = true;
    out->infos.push_back(
        "use_map_topic is false: as amcl then does, the first map is kept (it is read from the "
        "map topic, which map_server and map_publisher latch, instead of the static_map service)");
  }
  if (c.filter.sensor.beam_skip &&
      c.filter.laser_model_type != pf::LaserModelType::kLikelihoodFieldProb) {
    out->infos.push_back(
        "do_beamskip is true but laser_model_type is not likelihood_field_prob: "
        "beam skipping is part of likelihood_field_prob (as in amcl), so no beam "
        "is skipped");
  }
  reader.reportLeftovers();
  validate(c);
  if (notes == nullptr) logNotes(own_notes);
  return c;
}

void validate(const LocalizerConfig& c) {
  checkRanges(ownParameters(), c);
  pf::validate(c.cloud);
  scanWeights(c);  // throws, naming scan_weights
  if (sensorTopics(c).empty()) {
    throw std::invalid_argument(
        pf::invalidParameterMessage("scan_topics", "\"" + c.scan_topics + "\"",
                                    "at least one topic name (or one in cloud_topics)"));
  }
  pf::validate(c.filter);
}

}  // namespace pf_ros
