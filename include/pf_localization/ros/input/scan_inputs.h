// pf_node's sensor inputs: for each scan topic and each cloud topic a
// subscription and a tf message filter that holds each message until tf can
// place it (its odometry at the message's stamp), then hands it on with the
// index of its sensor (sensorTopics(): the scan topics, then the cloud topics).
#pragma once

#include <message_filters/subscriber.h>
#include <ros/callback_queue_interface.h>
#include <ros/node_handle.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace pf_ros {

class ScanInputs {
 public:
  using OnScan = std::function<void(const sensor_msgs::LaserScanConstPtr&, std::size_t sensor)>;
  using OnCloud = std::function<void(const sensor_msgs::PointCloud2ConstPtr&, std::size_t sensor)>;
  /// A message tf could not place: its header, and why.
  using OnDrop = std::function<void(const std_msgs::Header&,
                                    tf2_ros::filter_failure_reasons::FilterFailureReason)>;

  /// One input per topic of `scan_topics` (sensors 0, 1, ...) and of
  /// `cloud_topics` (the sensors after those); the filters wait for
  /// `odom_frame` and call back on `queue`. Nothing is subscribed before
  /// subscribe().
  ScanInputs(const std::vector<std::string>& scan_topics,
             const std::vector<std::string>& cloud_topics, tf2_ros::Buffer& buffer,
             const std::string& odom_frame, ros::CallbackQueueInterface* queue,
             const OnScan& on_scan, const OnCloud& on_cloud, const OnDrop& on_drop);

  /// Unsubscribes, then waits for the callbacks running on another thread.
  ~ScanInputs();
  ScanInputs(const ScanInputs&) = delete;
  ScanInputs& operator=(const ScanInputs&) = delete;

  /// Subscribes every topic (relative to `nh`): callbacks may run at once.
  void subscribe(ros::NodeHandle& nh);
  void unsubscribe();

 private:
  template <typename Message>
  struct Input {
    Input(const std::string& topic, tf2_ros::Buffer& buffer, const std::string& odom_frame,
          ros::CallbackQueueInterface* queue);
    std::string topic;
    message_filters::Subscriber<Message> subscriber;
    tf2_ros::MessageFilter<Message> filter;
  };
  template <typename Message, typename OnMessage>
  void addInputs(const std::vector<std::string>& topics, std::size_t first_sensor,
                 tf2_ros::Buffer& buffer, const std::string& odom_frame,
                 const OnMessage& on_message, const OnDrop& on_drop,
                 std::vector<std::unique_ptr<Input<Message>>>* inputs);

  ros::CallbackQueueInterface* queue_;
  std::vector<std::unique_ptr<Input<sensor_msgs::LaserScan>>> scans_;
  std::vector<std::unique_ptr<Input<sensor_msgs::PointCloud2>>> clouds_;
};

}  // namespace pf_ros
