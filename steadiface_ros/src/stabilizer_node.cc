// steadiface_node: the same StabilizerRos as the nodelet, in its own process.
#include <ros/ros.h>

#include "steadiface_ros/stabilizer_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "steadiface");
  ros::NodeHandle nh, pnh("~");
  steadiface_ros::StabilizerRos stabilizer(nh, pnh, ros::this_node::getName());
  if (!stabilizer.ok()) return 1;
  ros::spin();  // single-threaded, like the nodelet's default queue
  return 0;
}
