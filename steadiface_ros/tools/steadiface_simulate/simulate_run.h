#pragma once

#include <string>

#include <Eigen/Geometry>

#include "steadiface_core/sim/simulator.h"

namespace steadiface_simulate {

/// What steadiface_simulate records (its command line).
struct SimulateOptions {
  std::string preset = "walk";  ///< a simulator preset
  std::string out;              ///< the bag; the truth goes to <out>.truth.csv
  /// The simulator's photos and gyro logs (empty: the package's test/data).
  std::string data;
  /// The simulation (size, duration, rates, seed, clock offset, ...); the
  /// preset's settings are applied over it (sim::MakeSimulatorOptions).
  steadiface::sim::SimulatorOptions sim;
  bool mono = false;    ///< mono8 images instead of bgr8
  double epoch = 1.7e9;  ///< bag stamps start here [s] (a realistic ROS time)
  double readout = -1;   ///< the rolling-shutter readout [s]; < 0: the preset's
  std::string image_topic = "/camera/image_raw";
  std::string info_topic = "/camera/camera_info";  ///< "none": no camera_info
  std::string imu_topic = "/imu";  ///< "none": no IMU (a camera without one)
  std::string camera_frame = "camera_optical", imu_frame = "camera_optical";
  /// Also the intrinsics as a camera_calibration YAML (empty: none).
  std::string calibration_out;
  /// jpeg or png: sensor_msgs/CompressedImage on <image_topic>/compressed.
  std::string compress_images;
  /// The IMU's mounting: the gyro is recorded in IMU axes.
  Eigen::Quaterniond R_imu_cam = Eigen::Quaterniond::Identity();
};

/// Renders the preset into a bag (images, camera_info, IMU with angular
/// velocity, linear acceleration and orientation_covariance[0] = -1, in
/// time order as a recording would be; a preset's IMU dropout leaves a gap)
/// and its ground truth beside it.
/// Messages go to stderr, the summary line to stdout. Returns the
/// process's exit status: 0 written, 1 a failure.
int RunSimulation(const SimulateOptions& options);

}  // namespace steadiface_simulate
