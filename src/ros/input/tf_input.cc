#include "pf_localization/ros/input/tf_input.h"

#include <ros/callback_queue.h>

namespace pf_ros {

TfInput::TfInput(const ros::NodeHandle& nh)
    : buffer_(ros::Duration(30.0)), queue_(ros::getGlobalCallbackQueue()) {
  listener_ = std::make_unique<tf2_ros::TransformListener>(buffer_, onPollThread(nh), false);
}

TfInput::~TfInput() { listener_.reset(); }

}  // namespace pf_ros
