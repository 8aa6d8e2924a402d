// steadiface/StabilizerNodelet: a thin onInit around StabilizerRos.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "steadiface_ros/stabilizer_ros.h"

namespace steadiface_ros {

class StabilizerNodelet : public nodelet::Nodelet {
 public:
  ~StabilizerNodelet() override { stabilizer_.reset(); }

 private:
  void onInit() override {
    // Single-threaded callback queue: see StabilizerRos's threading model.
    stabilizer_.reset(new StabilizerRos(getNodeHandle(), getPrivateNodeHandle(), getName()));
  }
  std::unique_ptr<StabilizerRos> stabilizer_;
};

}  // namespace steadiface_ros

PLUGINLIB_EXPORT_CLASS(steadiface_ros::StabilizerNodelet, nodelet::Nodelet)
