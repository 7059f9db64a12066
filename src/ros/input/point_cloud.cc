#include "pf_localization/ros/input/point_cloud.h"

#include <sensor_msgs/PointField.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pf_ros {
namespace {

// The datatypes' names as sensor_msgs/PointField spells them.
std::string datatypeName(uint8_t datatype) {
  using F = sensor_msgs::PointField;
  switch (datatype) {
    case F::INT8:
      return "INT8";
    case F::UINT8:
      return "UINT8";
    case F::INT16:
      return "INT16";
    case F::UINT16:
      return "UINT16";
    case F::INT32:
      return "INT32";
    case F::UINT32:
      return "UINT32";
    case F::FLOAT32:
      return "FLOAT32";
    case F::FLOAT64:
      return "FLOAT64";
  }
  return "unknown datatype " + std::to_string(datatype);
}

bool machineIsBigEndian() {
  const uint16_t one = 1;
  return *reinterpret_cast<const uint8_t*>(&one) == 0;
}

CloudReadError error(CloudReadError::Kind kind, std::string detail) {
  return {kind, std::move(detail)};
}

// The x, y or z field's problem, if it has one.
std::optional<CloudReadError> checkField(const sensor_msgs::PointCloud2& msg,
                                         const std::string& name) {
  const sensor_msgs::PointField* field = nullptr;
  for (const sensor_msgs::PointField& f : msg.fields) {
    if (f.name == name) {
      field = &f;  // the first, as the iterators take
      break;
    }
  }
  if (!field) {
    std::string present;
    for (const sensor_msgs::PointField& f : msg.fields) {
      present += (present.empty() ? "" : ", ") + f.name;
    }
    return error(CloudReadError::Kind::kMissingField,
                 "the cloud has no field '" + name + "' (its fields: " +
                     (present.empty() ? "none" : present) + "); x, y and z are needed");
  }
  if (field->datatype != sensor_msgs::PointField::FLOAT32 || field->count != 1) {
    return error(CloudReadError::Kind::kWrongDatatype,
                 "field '" + name + "' is " + std::to_string(field->count) + " x " +
                     datatypeName(field->datatype) + "; x, y and z must be one FLOAT32 each");
  }
  if (static_cast<uint64_t>(field->offset) + sizeof(float) > msg.point_step) {
    return error(CloudReadError::Kind::kBadLayout, "field '" + name + "' at offset " +
                                                       std::to_string(field->offset) +
                                                       " does not fit in a point of point_step " +
                                                       std::to_string(msg.point_step) + " bytes");
  }
  return std::nullopt;
}

}  // namespace

const char* kindName(CloudReadError::Kind kind) {
  switch (kind) {
    case CloudReadError::Kind::kMissingField:
      return "missing field";
    case CloudReadError::Kind::kWrongDatatype:
      return "wrong datatype";
    case CloudReadError::Kind::kBigEndian:
      return "byte order";
    case CloudReadError::Kind::kBadLayout:
      return "bad layout";
  }
  return "unknown";
}

std::optional<CloudReadError> readCloud(const sensor_msgs::PointCloud2& msg,
                                        std::vector<pf::CloudPoint>* points) {
  points->clear();
  for (const char* name : {"x", "y", "z"}) {
    if (auto problem = checkField(msg, name)) return problem;
  }
  if (static_cast<bool>(msg.is_bigendian) != machineIsBigEndian()) {
    return error(CloudReadError::Kind::kBigEndian,
                 std::string("the cloud is ") + (msg.is_bigendian ? "big" : "little") +
                     "-endian (is_bigendian) and this machine is not; clouds are read in the "
                     "machine's byte order only");
  }
  const uint64_t width = msg.width, height = msg.height;
  if (width == 0 || height == 0) return std::nullopt;  // an empty cloud: nothing to read
  // Whole points per row: the iterators step by point_step only.
  if (msg.row_step < width * msg.point_step || msg.row_step % msg.point_step != 0) {
    return error(CloudReadError::Kind::kBadLayout,
                 "row_step " + std::to_string(msg.row_step) + " must be width " +
                     std::to_string(msg.width) + " x point_step " + std::to_string(msg.point_step) +
                     " or a larger multiple of point_step");
  }
  if (msg.data.size() < (height - 1) * msg.row_step + width * msg.point_step) {
    return error(CloudReadError::Kind::kBadLayout,
                 "data holds " + std::to_string(msg.data.size()) + " bytes, fewer than " +
                     std::to_string(msg.height) + " rows of row_step " +
                     std::to_string(msg.row_step) + " need");
  }

  // An empty cloud has no data for an iterator to point into (UBSan: a
  // reference bound to a null pointer).
  if (width * height == 0) {
    points->clear();
    return std::nullopt;
  }
  points->resize(width * height);
  const int points_per_row = static_cast<int>(msg.row_step / msg.point_step);
  sensor_msgs::PointCloud2ConstIterator<float> row_x(msg, "x"), row_y(msg, "y"), row_z(msg, "z");
  pf::CloudPoint* out = points->data();
  for (uint64_t r = 0; r < height; ++r) {
    sensor_msgs::PointCloud2ConstIterator<float> x = row_x, y = row_y, z = row_z;
    for (uint64_t c = 0; c < width; ++c, ++x, ++y, ++z) *out++ = {*x, *y, *z};
    if (r + 1 < height) {
      row_x += points_per_row;
      row_y += points_per_row;
      row_z += points_per_row;
    }
  }
  return std::nullopt;
}

pf::SensorMount toSensorMount(const geometry_msgs::Transform& t) {
  const Eigen::Quaterniond q(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z);
  const double norm = q.norm();
  pf::SensorMount mount;
  // Eigen's normalized() leaves a zero quaternion as it is, and its matrix is
  // the identity: a rotation nobody gave must not pass for a level mounting.
  if (norm > 0.0 && std::isfinite(norm)) {
    mount.rotation = Eigen::Quaterniond(q.coeffs() / norm).toRotationMatrix();
  } else {
    mount.rotation.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  mount.translation << t.translation.x, t.translation.y, t.translation.z;
  return mount;
}

}  // namespace pf_ros
