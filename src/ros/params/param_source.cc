#include "pf_localization/ros/params/param_source.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "pf_localization/core/util/parameter_table.h"

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

template <typename T>
const char* expected() {
  if constexpr (std::is_same_v<T, double>) return "a number";
  if constexpr (std::is_same_v<T, int>) return "an integer";
  if constexpr (std::is_same_v<T, bool>) return "true or false";
  return "a string";
}

class YamlParamSource : public TypedParamSource<YamlParamSource> {
 public:
  YamlParamSource(YAML::Node root, std::string path)
      : root_(std::move(root)), path_(std::move(path)) {}

  template <typename T>
  bool read(const std::string& key, T* value) const {
    const YAML::Node node = root_[key];
    if (!node || node.IsNull()) return false;
    try {
      if constexpr (std::is_same_v<T, std::string>) {
        // A list (scan_topics: [a, b]) as its elements separated by spaces.
        if (node.IsSequence()) {
          std::string joined;
          for (const YAML::Node& element : node) {
            joined += (joined.empty() ? "" : " ") + element.as<std::string>();
          }
          *value = joined;
          return true;
        }
      }
      *value = node.as<T>();
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(path_ + ": parameter " + key + " has the wrong type: expected " +
                                  expected<T>() + ", got '" + YAML::Dump(node) + "'");
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
      throw std::invalid_argument("parameter " + nh_.resolveName(key) +
                                  " has the wrong type: expected " + expected<T>() + ", got " +
                                  typeName(*v));
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

  static std::string typeName(XmlRpc::XmlRpcValue& v) {
    switch (v.getType()) {
      case XmlRpc::XmlRpcValue::TypeBoolean:
        return std::string("the boolean ") + (static_cast<bool>(v) ? "true" : "false");
      case XmlRpc::XmlRpcValue::TypeInt:
        return "the integer " + std::to_string(static_cast<int>(v));
      case XmlRpc::XmlRpcValue::TypeDouble:
        return "the number " + pf::formatNumber(static_cast<double>(v));
      case XmlRpc::XmlRpcValue::TypeString:
        return "the string '" + static_cast<std::string>(v) + "'";
      default:
        return "a list, a dictionary or a date";
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
  // A text; a number as it reads; a list (scan_topics: [a, b]) as its
  // elements separated by spaces, as the list parameters take it.
  static bool convert(XmlRpc::XmlRpcValue& v, std::string* out) {
    switch (v.getType()) {
      case XmlRpc::XmlRpcValue::TypeString:
        *out = static_cast<std::string>(v);
        return true;
      case XmlRpc::XmlRpcValue::TypeInt:
        *out = std::to_string(static_cast<int>(v));
        return true;
      case XmlRpc::XmlRpcValue::TypeDouble:
        *out = pf::formatNumber(static_cast<double>(v));
        return true;
      case XmlRpc::XmlRpcValue::TypeArray: {
        std::string joined;
        for (int i = 0; i < v.size(); ++i) {
          std::string element;
          if (v[i].getType() == XmlRpc::XmlRpcValue::TypeArray || !convert(v[i], &element)) {
            return false;
          }
          joined += (i > 0 ? " " : "") + element;
        }
        *out = joined;
        return true;
      }
      default:
        return false;
    }
  }

  ros::NodeHandle nh_;
  // Mutable: XmlRpcValue's accessors are not const.
  mutable XmlRpc::XmlRpcValue params_;
};

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

}  // namespace pf_ros
