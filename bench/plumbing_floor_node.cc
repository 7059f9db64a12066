// pf_plumbing_floor: what any roscpp localizer pays for its messages alone.
//
// It takes /tf and the scans as pf_node does (on roscpp's poll thread, through
// pf_ros::InlineCallbackQueue) and, for every scan, publishes map -> odom
// on /tf and one pose, as amcl does after each update; there is no map, no
// filter and nothing else. Run on a bag in place of pf_node, its CPU time is
// the floor under pf_node's: on a virtual machine, where a system call costs
// microseconds, receiving and sending messages through roscpp is most of a
// light localizer's CPU (docs/performance.md). scripts/live_cpu.sh runs
// both on the same bag, in turn.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "pf_localization/ros/scheduling/inline_callback_queue.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "pf_node");
  ros::NodeHandle nh;
  pf_ros::InlineCallbackQueue inline_queue(ros::getGlobalCallbackQueue());
  ros::NodeHandle inline_nh = pf_ros::withQueue(nh, &inline_queue);
  tf2_ros::Buffer buffer(ros::Duration(30.0));
  tf2_ros::TransformListener listener(buffer, inline_nh, false);
  tf2_ros::TransformBroadcaster broadcaster;
  ros::Publisher pose_pub =
      nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("amcl_pose", 2, true);
  const auto on_scan = [&](const sensor_msgs::LaserScanConstPtr& scan) {
    geometry_msgs::TransformStamped map_to_odom;
    map_to_odom.header.stamp = scan->header.stamp + ros::Duration(0.1);
    map_to_odom.header.frame_id = "map";
    map_to_odom.child_frame_id = "odom";
    map_to_odom.transform.rotation.w = 1.0;
    broadcaster.sendTransform(map_to_odom);
    geometry_msgs::PoseWithCovarianceStamped pose;
    pose.header.stamp = scan->header.stamp;
    pose.header.frame_id = "map";
    pose.pose.pose.orientation.w = 1.0;
    pose_pub.publish(pose);
  };
  ros::Subscriber scan_sub = inline_nh.subscribe<sensor_msgs::LaserScan>("scan", 20, on_scan);
  ros::spin();
  return 0;
}
