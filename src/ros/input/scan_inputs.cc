#include "pf_localization/ros/input/scan_inputs.h"

namespace pf_ros {

// 20 messages may wait for their odometry: a second of a fast lidar.
constexpr uint32_t kQueueSize = 20;

template <typename Message>
ScanInputs::Input<Message>::Input(const std::string& topic_name, tf2_ros::Buffer& buffer,
                                  const std::string& odom_frame, ros::CallbackQueueInterface* queue)
    : topic(topic_name), filter(buffer, odom_frame, kQueueSize, queue) {
  filter.connectInput(subscriber);
}

template <typename Message, typename OnMessage>
void ScanInputs::addInputs(const std::vector<std::string>& topics, std::size_t first_sensor,
                           tf2_ros::Buffer& buffer, const std::string& odom_frame,
                           const OnMessage& on_message, const OnDrop& on_drop,
                           std::vector<std::unique_ptr<Input<Message>>>* inputs) {
  using Ptr = boost::shared_ptr<const Message>;
  for (std::size_t i = 0; i < topics.size(); ++i) {
    auto input = std::make_unique<Input<Message>>(topics[i], buffer, odom_frame, queue_);
    const std::size_t sensor = first_sensor + i;
    input->filter.registerCallback(
        [on_message, sensor](const Ptr& message) { on_message(message, sensor); });
    input->filter.registerFailureCallback(
        [on_drop](const Ptr& message, tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          on_drop(message->header, reason);
        });
    inputs->push_back(std::move(input));
  }
}

ScanInputs::ScanInputs(const std::vector<std::string>& scan_topics,
                       const std::vector<std::string>& cloud_topics, tf2_ros::Buffer& buffer,
                       const std::string& odom_frame, ros::CallbackQueueInterface* queue,
                       const OnScan& on_scan, const OnCloud& on_cloud, const OnDrop& on_drop)
    : queue_(queue) {
  addInputs(scan_topics, 0, buffer, odom_frame, on_scan, on_drop, &scans_);
  addInputs(cloud_topics, scan_topics.size(), buffer, odom_frame, on_cloud, on_drop, &clouds_);
}

ScanInputs::~ScanInputs() { unsubscribe(); }

void ScanInputs::subscribe(ros::NodeHandle& nh) {
  for (const auto& input : scans_) {
    input->subscriber.subscribe(nh, input->topic, kQueueSize, ros::TransportHints(), queue_);
  }
  for (const auto& input : clouds_) {
    input->subscriber.subscribe(nh, input->topic, kQueueSize, ros::TransportHints(), queue_);
  }
}

void ScanInputs::unsubscribe() {
  for (const auto& input : scans_) input->subscriber.unsubscribe();
  for (const auto& input : clouds_) input->subscriber.unsubscribe();
}

}  // namespace pf_ros
