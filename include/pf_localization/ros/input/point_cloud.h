// sensor_msgs/PointCloud2 read into the core's cloud input (core/cloud_scan_reducer.h):
// the x, y and z of every point, through sensor_msgs' PointCloud2ConstIterator.
//
// A cloud is read if its x, y and z fields are float32 (the type every lidar
// and depth-camera driver publishes), its byte order is the machine's, and
// its layout holds together (the fields inside a point, the rows inside
// the data). Anything else is a CloudReadError: the iterators check none of
// it and would read past the buffer. Organized clouds (height > 1, a depth
// image or a lidar's rings) and unorganized ones (height 1) are read alike,
// row by row; rows may be padded by whole points (row_step a multiple of
// point_step). Points without a return (NaN) are read as they are: the
// reducer counts them (CloudScanCounts::not_finite), they are no error.
#pragma once

#include <geometry_msgs/Transform.h>
#include <sensor_msgs/PointCloud2.h>

#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/sensor/cloud_scan_reducer.h"

namespace pf_ros {

/// Why a cloud was not read. `kind` is for code to branch on, `detail` for a
/// person: it names the field, the type or the sizes that are wrong.
struct CloudReadError {
  enum class Kind {
    kMissingField,   // no field named x, y or z
    kWrongDatatype,  // x, y or z is not one float32 (PointField::FLOAT32, count 1)
    kBigEndian,      // byte order other than the machine's
    kBadLayout,      // a field beyond point_step, rows beyond the data, ...
  };
  Kind kind;
  std::string detail;
};

/// "missing field", "wrong datatype", "byte order", "bad layout".
const char* kindName(CloudReadError::Kind kind);

/// Reads every point of `msg` into `*points` (cleared first; width * height
/// points in row order). Returns the error instead, leaving `*points`
/// empty, when the cloud cannot be read (see the top of this file).
std::optional<CloudReadError> readCloud(const sensor_msgs::PointCloud2& msg,
                                        std::vector<pf::CloudPoint>* points);

/// The sensor's mounting from tf's transform base <- sensor frame. The
/// quaternion is normalised (hand-written static transforms often are not
/// unit length); a zero or NaN one gives a mounting that
/// pf::validateMount refuses.
pf::SensorMount toSensorMount(const geometry_msgs::Transform& base_from_sensor);

}  // namespace pf_ros
