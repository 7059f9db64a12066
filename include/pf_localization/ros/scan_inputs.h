// pf_node's lidar inputs: for each scan topic a subscription and a tf message
// filter that holds each scan until tf can place it (its odometry at the
// scan's stamp), then hands it on with the index of its topic, the sensor.
#pragma once

#include <message_filters/subscriber.h>
#include <ros/callback_queue_interface.h>
#include <ros/node_handle.h>
#include <sensor_msgs/LaserScan.h>
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
  using OnDrop = std::function<void(const sensor_msgs::LaserScanConstPtr&,
                                    tf2_ros::filter_failure_reasons::FilterFailureReason)>;

  /// One input per topic of `topics`; the filters wait for `odom_frame` and
  /// call back on `queue`. Nothing is subscribed before subscribe().
  ScanInputs(const std::vector<std::string>& topics, tf2_ros::Buffer& buffer,
             const std::string& odom_frame, ros::CallbackQueueInterface* queue,
             const OnScan& on_scan, const OnDrop& on_drop);

  /// Subscribes every topic (relative to `nh`): callbacks may run at once.
  void subscribe(ros::NodeHandle& nh);
  void unsubscribe();

 private:
  struct Input {
    Input(tf2_ros::Buffer& buffer, const std::string& odom_frame,
          ros::CallbackQueueInterface* queue);
    message_filters::Subscriber<sensor_msgs::LaserScan> subscriber;
    tf2_ros::MessageFilter<sensor_msgs::LaserScan> filter;
  };
  std::vector<std::string> topics_;
  ros::CallbackQueueInterface* queue_;
  std::vector<std::unique_ptr<Input>> inputs_;
};

}  // namespace pf_ros
