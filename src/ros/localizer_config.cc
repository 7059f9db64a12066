#include "pf_localization/ros/localizer_config.h"

#include <ros/console.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "pf_localization/core/parameter_check.h"
#include "pf_localization/ros/amcl_params.h"

namespace pf_ros {
namespace {

// The four typed getters of ParamSource, all forwarded to the derived
// class's one template read().
template <typename Derived>
class TypedParamSource : public ParamSource {
 public:
  bool get(const std::string& key, double* value) const override { return self().read(key, value); }
  bool get(const std::string& key, int* value) const override { return self().read(key, value); }
  bool get(const std::string& key, bool* value) const override { return self().read(key, value); }
  bool get(const std::string& key, std::string* value) const override {
    return self().read(key, value);
  }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }
};

class YamlParamSource : public TypedParamSource<YamlParamSource> {
 public:
  YamlParamSource(YAML::Node root, std::string path)
      : root_(std::move(root)), path_(std::move(path)) {}

  template <typename T>
  bool read(const std::string& key, T* value) const {
    const YAML::Node node = root_[key];
    if (!node || node.IsNull()) return false;
    try {
      *value = node.as<T>();
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(path_ + ": parameter " + key + " has the wrong type");
    }
    return true;
  }

  std::vector<std::string> keys() const override {
    std::vector<std::string> names;
    if (!root_.IsMap()) return names;
    for (const auto& entry : root_) names.push_back(entry.first.as<std::string>());
    return names;
  }

 private:
  YAML::Node root_;
  std::string path_;
};

// A node's namespace, fetched from the master in one call when constructed:
// NodeHandle::hasParam and getParam make a round trip to the master each,
// and readConfig looks up about a hundred names and their amcl aliases, over
// 200 round trips at start-up. Values convert as getParam converts them: an
// int is a double too, and a double is rounded to an int by getParam's rule
// (up from a fractional part of 0.5; beyond an int's range, clamped, so that
// the range check names the value).
class RosParamSource : public TypedParamSource<RosParamSource> {
 public:
  explicit RosParamSource(const ros::NodeHandle& nh) : nh_(nh) {
    if (!nh_.getParam(nh_.getNamespace(), params_) ||
        params_.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
      params_ = XmlRpc::XmlRpcValue();  // no parameters at all
    }
  }

  template <typename T>
  bool read(const std::string& key, T* value) const {
    XmlRpc::XmlRpcValue* v = find(key);
    if (v == nullptr) return false;
    if (!convert(*v, value)) {
      throw std::invalid_argument("parameter " + nh_.resolveName(key) + " has the wrong type");
    }
    return true;
  }

  std::vector<std::string> keys() const override {
    std::vector<std::string> names;
    if (params_.getType() != XmlRpc::XmlRpcValue::TypeStruct) return names;
    for (const auto& entry : params_) names.push_back(entry.first);
    return names;
  }

 private:
  // The value at `key` ("a/b" looks inside a), or nullptr.
  XmlRpc::XmlRpcValue* find(const std::string& key) const {
    XmlRpc::XmlRpcValue* v = &params_;
    std::size_t start = 0;
    while (true) {
      const std::size_t slash = key.find('/', start);
      const std::string name = key.substr(start, slash - start);
      if (v->getType() != XmlRpc::XmlRpcValue::TypeStruct || !v->hasMember(name)) return nullptr;
      v = &(*v)[name];
      if (slash == std::string::npos) return v;
      start = slash + 1;
    }
  }

  static bool convert(XmlRpc::XmlRpcValue& v, double* out) {
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      *out = static_cast<int>(v);
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      *out = static_cast<double>(v);
    } else {
      return false;
    }
    return true;
  }
  static bool convert(XmlRpc::XmlRpcValue& v, int* out) {
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      const double d = v;
      if (std::isnan(d)) return false;
      const double rounded = std::fmod(d, 1.0) < 0.5 ? std::floor(d) : std::ceil(d);
      *out = static_cast<int>(std::clamp<double>(rounded, std::numeric_limits<int>::min(),
                                                 std::numeric_limits<int>::max()));
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      *out = static_cast<int>(v);
    } else {
      return false;
    }
    return true;
  }
  static bool convert(XmlRpc::XmlRpcValue& v, bool* out) {
    if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) return false;
    *out = static_cast<bool>(v);
    return true;
  }
  static bool convert(XmlRpc::XmlRpcValue& v, std::string* out) {
    if (v.getType() != XmlRpc::XmlRpcValue::TypeString) return false;
    *out = static_cast<std::string>(v);
    return true;
  }

  ros::NodeHandle nh_;
  // Mutable: XmlRpcValue's accessors are not const.
  mutable XmlRpc::XmlRpcValue params_;
};

void require(bool ok, const std::string& name, const std::string& range) {
  if (!ok) throw std::invalid_argument("invalid parameter " + name + ": must be " + range);
}

template <typename T>
std::string show(const T& value) {
  std::ostringstream s;
  s << std::boolalpha << value;
  return s.str();
}

// Whether our `name` set to `ours` and its amcl alias set to `amcls` mean the same.
template <typename T>
bool agree(const std::string&, const T& ours, const T& amcls) {
  return ours == amcls;
}

bool agree(const std::string& name, const double& ours, const double& amcls) {
  if (name == "kld_confidence") return std::fabs(kldConfidenceFromZ(amcls) - ours) < 1e-9;
  return ours == amcls;
}

// Looks each setting up under our name and amcl's, in the user's source
// before the defaults, and remembers every name asked for: whatever else the
// source holds is reported as unknown (a misspelt name would otherwise be
// silently ignored, the classic amcl configuration bug).
class ParamReader {
 public:
  ParamReader(const ParamSource& source, const ParamSource* defaults, ConfigNotes* notes)
      : source_(source), defaults_(defaults), notes_(notes) {}

  /// The name the value was found under; empty when absent (value untouched).
  template <typename T>
  std::string get(const std::string& name, T* value) {
    known_.insert(name);
    const std::optional<std::string> alias = amclAliasOf(name);
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
    std::string unknown;
    for (const std::string& key : source_.keys()) {
      // "defaults" is the namespace launch/amcl_compatible.launch loads config/pf.yaml into.
      if (known_.count(key) || unused_amcl.count(key) || key == "defaults") continue;
      unknown += (unknown.empty() ? "" : ", ") + key;
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

std::unique_ptr<ParamSource> yamlParamSource(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read parameters: " + e.what());
  }
  if (!root.IsMap() && !root.IsNull()) throw std::runtime_error(path + ": not a YAML mapping");
  return std::make_unique<YamlParamSource>(root, path);
}

std::unique_ptr<ParamSource> rosParamSource(const ros::NodeHandle& nh) {
  return std::make_unique<RosParamSource>(nh);
}

LocalizerConfig readConfig(const ParamSource& source, const ParamSource* defaults,
                           ConfigNotes* notes) {
  ConfigNotes own_notes;
  ConfigNotes* out = notes != nullptr ? notes : &own_notes;
  ParamReader p(source, defaults, out);
  LocalizerConfig c;
  p.get("global_frame", &c.global_frame);
  p.get("odom_frame", &c.odom_frame);
  p.get("base_frame", &c.base_frame);
  // tf2 refuses frame ids with a leading slash, which tf (and so many amcl
  // configurations) used; amcl strips it too.
  for (std::string* frame : {&c.global_frame, &c.odom_frame, &c.base_frame}) {
    if (!frame->empty() && frame->front() == '/') frame->erase(0, 1);
  }
  p.get("tf_broadcast", &c.tf_broadcast);
  p.get("transform_tolerance", &c.transform_tolerance);
  p.get("tf_publish_rate", &c.tf_publish_rate);

  p.get("deskew_scans", &c.deskew_scans);
  p.get("scan_stamp", &c.scan_stamp);
  require(c.scan_stamp == "first_beam" || c.scan_stamp == "last_beam", "scan_stamp",
          "first_beam or last_beam (got '" + c.scan_stamp + "')");

  pf::Pose2 initial{std::nan(""), std::nan(""), 0.0};
  p.get("initial_pose_x", &initial.x);
  p.get("initial_pose_y", &initial.y);
  p.get("initial_pose_a", &initial.yaw);
  if (std::isfinite(initial.x) && std::isfinite(initial.y)) {
    require(std::isfinite(initial.yaw), "initial_pose_a", "a finite angle in rad");
    c.initial_pose = initial;
  }
  double cov_xx = c.initial_cov(0, 0), cov_yy = c.initial_cov(1, 1), cov_aa = c.initial_cov(2, 2);
  p.get("initial_cov_xx", &cov_xx);
  p.get("initial_cov_yy", &cov_yy);
  p.get("initial_cov_aa", &cov_aa);
  require(cov_xx >= 0.0 && std::isfinite(cov_xx), "initial_cov_xx", ">= 0 (m^2)");
  require(cov_yy >= 0.0 && std::isfinite(cov_yy), "initial_cov_yy", ">= 0 (m^2)");
  require(cov_aa >= 0.0 && std::isfinite(cov_aa), "initial_cov_aa", ">= 0 (rad^2)");
  c.initial_cov = Eigen::Vector3d(cov_xx, cov_yy, cov_aa).asDiagonal();

  pf::ParticleFilterParams& f = c.filter;
  p.get("min_particles", &f.kld.min_particles);
  p.get("max_particles", &f.kld.max_particles);
  p.get("kld_err", &f.kld.kld_err);
  double kld = f.kld.confidence;
  if (p.get("kld_confidence", &kld) == "kld_z") {
    const double z = kld;
    kld = kldConfidenceFromZ(z);
    require(std::isfinite(z) && kld > 0.0 && kld < 1.0, "kld_z",
            "a finite normal quantile between -8 and 8 (amcl's default: 0.99)");
  }
  f.kld.confidence = kld;
  p.get("kld_bin_xy", &f.kld.bin_xy);
  p.get("kld_bin_yaw", &f.kld.bin_yaw);
  p.get("update_min_d", &f.update_min_d);
  p.get("update_min_a", &f.update_min_a);
  p.get("update_fit_drop", &f.update_fit_drop);
  p.get("update_fit_distance", &f.update_fit_distance);
  p.get("odom_jump_limit", &f.odom_jump_limit);
  p.get("resample_ess_fraction", &f.resample_ess_fraction);
  p.get("tempering_ess_fraction", &f.tempering_ess_fraction);
  p.get("tempering_ess_fraction_uncertain", &f.tempering_ess_fraction_uncertain);
  p.get("confidence_hit_distance", &f.confidence.hit_distance);
  p.get("confidence_lost_hit_fraction", &f.confidence.lost_hit_fraction);
  p.get("confidence_localized_hit_fraction", &f.confidence.localized_hit_fraction);
  p.get("confidence_localized_std_xy", &f.confidence.localized_std_xy);
  p.get("confidence_localized_std_yaw", &f.confidence.localized_std_yaw);
  p.get("confidence_rival_weight_ratio", &f.confidence.rival_weight_ratio);
  p.get("confidence_jump_distance", &f.confidence.jump_distance);
  p.get("confidence_jump_yaw", &f.confidence.jump_yaw);
  p.get("confidence_settle_updates", &f.confidence.settle_updates);
  int seed = 0;
  if (!p.get("seed", &seed).empty()) {
    require(seed >= 0, "seed", ">= 0");
    f.seed = static_cast<uint64_t>(seed);
  }
  p.get("cluster_xy", &f.clusters.cell_xy);
  p.get("cluster_yaw", &f.clusters.cell_yaw);
  p.get("cluster_join_weight_ratio", &f.clusters.join_weight_ratio);
  p.get("recovery_alpha_slow", &f.recovery.alpha_slow);
  p.get("recovery_alpha_fast", &f.recovery.alpha_fast);
  p.get("recovery_trigger_ratio", &f.recovery.trigger_ratio);
  p.get("recovery_kidnap_prior", &f.recovery.kidnap_prior);
  p.get("recovery_patience", &f.recovery.patience);
  p.get("recovery_patience_localized", &f.recovery.patience_localized);
  p.get("recovery_lost_share", &f.recovery.lost_share);
  p.get("recovery_expansion_ratio", &f.recovery.expansion_ratio);
  p.get("recovery_expansion_std_xy", &f.recovery.expansion_std_xy);
  p.get("recovery_expansion_std_yaw", &f.recovery.expansion_std_yaw);
  p.get("refine_estimate", &f.refine_estimate);
  p.get("refine_max_beams", &f.refiner.max_beams);
  p.get("refine_max_iterations", &f.refiner.max_iterations);
  p.get("refine_outlier_distance", &f.refiner.outlier_distance);
  p.get("refine_cauchy_scale", &f.refiner.cauchy_scale);
  p.get("refine_wall_offset", &f.refiner.wall_offset);
  p.get("refine_min_matched_fraction", &f.refiner.min_matched_fraction);
  p.get("refine_min_matched_beams", &f.refiner.min_matched_beams);
  p.get("refine_max_translation", &f.refiner.max_translation);
  p.get("refine_max_rotation", &f.refiner.max_rotation);
  p.get("refine_min_beam_std", &f.refiner.min_beam_std);
  p.get("refine_degeneracy_ratio", &f.refiner.degeneracy_ratio);
  p.get("refine_beam_std", &f.refiner.beam_std);
  p.get("refine_convergence", &f.refiner.convergence);

  std::string odom_model = "diff";
  p.get("odom_model_type", &odom_model);
  // amcl's "-corrected" variants fixed bugs of its own; the models here are the corrected ones.
  if (odom_model == "diff" || odom_model == "diff-corrected") {
    f.motion.kind = pf::OdometryMotionParams::Kind::kDifferential;
  } else if (odom_model == "omni" || odom_model == "omni-corrected") {
    f.motion.kind = pf::OdometryMotionParams::Kind::kOmni;
  } else {
    require(false, "odom_model_type", "diff or omni, got '" + odom_model + "'");
  }
  p.get("odom_alpha1", &f.motion.alpha1);
  p.get("odom_alpha2", &f.motion.alpha2);
  p.get("odom_alpha3", &f.motion.alpha3);
  p.get("odom_alpha4", &f.motion.alpha4);
  p.get("odom_alpha5", &f.motion.alpha5);
  p.get("odom_fault_fraction", &f.motion.fault_fraction);
  p.get("odom_fault_fraction_max", &f.motion.fault_fraction_max);
  p.get("odom_fault_suspect_fraction", &f.motion.fault_suspect_fraction);
  p.get("odom_fault_margin", &f.motion.fault_margin);

  p.get("laser_max_beams", &f.sensor.max_beams);
  p.get("sensor_threads", &f.sensor.threads);
  p.get("laser_z_hit", &f.sensor.z_hit);
  p.get("laser_z_rand", &f.sensor.z_rand);
  p.get("laser_sigma_hit", &f.sensor.sigma_hit);
  p.get("laser_likelihood_max_dist", &f.sensor.max_distance);
  p.get("laser_likelihood_exponent", &f.sensor.likelihood_exponent);
  p.get("laser_min_range", &f.sensor.range_min);
  p.get("laser_max_range", &f.sensor.range_max);
  // amcl spells "use the scan's own limit" as -1; accept that spelling too.
  f.sensor.range_min = std::max(f.sensor.range_min, 0.0);
  f.sensor.range_max = std::max(f.sensor.range_max, 0.0);
  std::string laser_model = "likelihood_field";
  p.get("laser_model_type", &laser_model);
  const std::string laser_model_error = laserModelTypeError(laser_model);
  if (!laser_model_error.empty()) throw std::invalid_argument(laser_model_error);
  f.laser_model_type = laser_model == "beam" ? pf::LaserModelType::kBeam
                       : laser_model == "likelihood_field_prob"
                           ? pf::LaserModelType::kLikelihoodFieldProb
                           : pf::LaserModelType::kLikelihoodField;
  p.get("laser_z_short", &f.beam.z_short);
  p.get("laser_z_max", &f.beam.z_max);
  p.get("laser_lambda_short", &f.beam.lambda_short);
  // Beam skipping is part of likelihood_field_prob only, as in amcl; the
  // filter ignores it under the other models. amcl reads its misspelt
  // beam_skip_error_threshold_ (an alias here).
  p.get("do_beamskip", &f.sensor.beam_skip);
  p.get("beam_skip_distance", &f.sensor.beam_skip_distance);
  p.get("beam_skip_threshold", &f.sensor.beam_skip_threshold);
  p.get("beam_skip_error_threshold", &f.sensor.beam_skip_error_threshold);
  if (f.sensor.beam_skip && f.laser_model_type != pf::LaserModelType::kLikelihoodFieldProb) {
    out->infos.push_back("do_beamskip is true but laser_model_type is " + laser_model +
                         ": beam skipping is part of likelihood_field_prob (as in amcl), so no "
                         "beam is skipped");
  }

  p.get("gui_publish_rate", &c.gui_publish_rate);
  p.get("cloud_max_poses", &c.cloud_max_poses);
  p.get("max_update_time", &c.max_update_time);
  p.get("save_pose_rate", &c.save_pose_rate);
  p.get("first_map_only", &c.first_map_only);
  bool use_map_topic = true;
  if (!p.get("use_map_topic", &use_map_topic).empty() && !use_map_topic && !c.first_map_only) {
    // amcl then asks map_server's static_map service once and never updates
    // its map. map_server publishes the same map latched on the map topic, so
    // taking the first map from there and keeping it behaves the same.
    c.first_map_only = true;
    out->infos.push_back(
        "use_map_topic is false: as amcl then does, the first map is kept (it is read from the "
        "map topic, which map_server and map_publisher latch, instead of the static_map service)");
  }
  p.reportLeftovers();
  validate(c);
  if (notes == nullptr) logNotes(own_notes);
  return c;
}

void validate(const LocalizerConfig& c) {
  require(!c.global_frame.empty(), "global_frame", "a frame name");
  require(!c.odom_frame.empty(), "odom_frame", "a frame name");
  require(!c.base_frame.empty(), "base_frame", "a frame name");
  // Numbers as the core words them, value included.
  pf::requireParameter(c.transform_tolerance >= 0.0 && std::isfinite(c.transform_tolerance),
                       "transform_tolerance", ">= 0 (s)", c.transform_tolerance);
  pf::requireParameter(c.tf_publish_rate > 0.0 && std::isfinite(c.tf_publish_rate),
                       "tf_publish_rate", "> 0 (Hz)", c.tf_publish_rate);
  pf::requireParameter(std::isfinite(c.gui_publish_rate), "gui_publish_rate",
                       "finite (Hz; <= 0: no limit)", c.gui_publish_rate);
  pf::requireParameter(c.cloud_max_poses >= 0, "cloud_max_poses", ">= 0 (poses; 0: every particle)",
                       c.cloud_max_poses);
  pf::requireParameter(std::isfinite(c.max_update_time) && c.max_update_time <= 10.0,
                       "max_update_time", "finite and <= 10 (s; <= 0: no limit)",
                       c.max_update_time);
  pf::requireParameter(std::isfinite(c.save_pose_rate), "save_pose_rate",
                       "finite (Hz; <= 0: never)", c.save_pose_rate);
  pf::validate(c.filter);
}

}  // namespace pf_ros
