#include "pf_localization/ros/scan_inputs.h"

namespace pf_ros {

// 20 scans may wait for their odometry: a second of a fast lidar.
constexpr uint32_t kQueueSize = 20;

ScanInputs::Input::Input(tf2_ros::Buffer& buffer, const std::string& odom_frame,
                         ros::CallbackQueueInterface* queue)
    : filter(buffer, odom_frame, kQueueSize, queue) {
  filter.connectInput(subscriber);
}

ScanInputs::ScanInputs(const std::vector<std::string>& topics, tf2_ros::Buffer& buffer,
                       const std::string& odom_frame, ros::CallbackQueueInterface* queue,
                       const OnScan& on_scan, const OnDrop& on_drop)
    : topics_(topics), queue_(queue) {
  for (std::size_t sensor = 0; sensor < topics_.size(); ++sensor) {
    auto input = std::make_unique<Input>(buffer, odom_frame, queue);
    input->filter.registerCallback(
        [on_scan, sensor](const sensor_msgs::LaserScanConstPtr& scan) { on_scan(scan, sensor); });
    input->filter.registerFailureCallback(on_drop);
    inputs_.push_back(std::move(input));
  }
}

void ScanInputs::subscribe(ros::NodeHandle& nh) {
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    inputs_[i]->subscriber.subscribe(nh, topics_[i], kQueueSize, ros::TransportHints(), queue_);
  }
}

void ScanInputs::unsubscribe() {
  for (const auto& input : inputs_) input->subscriber.unsubscribe();
}

}  // namespace pf_ros
