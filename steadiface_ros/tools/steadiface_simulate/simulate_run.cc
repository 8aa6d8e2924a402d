#include "steadiface_simulate/simulate_run.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>

#include <camera_calibration_parsers/parse.h>
#include <cv_bridge/cv_bridge.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <ros/package.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/image_encodings.h>

#include "steadiface_core/sim/truth_file.h"
#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/time_conversion.h"

namespace steadiface_simulate {
namespace {

using steadiface::Status;

// What the truth file records to rebuild this simulation (the data folder
// absolute, so the bag can be scored from anywhere), and the simulator.
Status MakeSimulation(const SimulateOptions& o, steadiface::sim::SimulationSettings* settings,
                      steadiface::sim::SimulatorOptions* so,
                      std::unique_ptr<steadiface::sim::Simulator>* sim) {
  const std::string data =
      o.data.empty() ? ros::package::getPath("steadiface") + "/test/data" : o.data;
  settings->preset = o.preset;
  char* abs_data = realpath(data.c_str(), nullptr);
  settings->data_dir = abs_data ? abs_data : data;
  free(abs_data);
  settings->base = o.sim;
  settings->readout_s = o.readout;
  settings->epoch_s = o.epoch;
  Status s = steadiface::sim::MakeSimulatorOptions(*settings, so);
  if (s.ok()) s = steadiface::sim::Simulator::Create(*so, sim);
  return s;
}

// Writes the simulation's messages into a bag: IMU and frames interleaved
// in time order.
class Recorder {
 public:
  Recorder(const SimulateOptions& o, const steadiface::sim::Simulator& sim, rosbag::Bag* bag)
      : o_(o), sim_(sim), bag_(bag), shift_(o.epoch) {}
  ros::Time ToRos(steadiface::Time t) const { return steadiface_ros::ToRosTime(t) + shift_; }
  // Writes the IMU samples not yet written whose stamps are <= until (all
  // if null).
  void WriteImu(const ros::Time* until);
  // Frame i and the IMU samples up to its last row, which precede it.
  Status WriteFrame(int i, double readout_s, steadiface::sim::TruthFileWriter* truth_file);

 private:
  const SimulateOptions& o_;
  const steadiface::sim::Simulator& sim_;
  rosbag::Bag* bag_;
  const ros::Duration shift_;
  size_t g_ = 0;
};

void Recorder::WriteImu(const ros::Time* until) {
  if (o_.imu_topic == "none") return;  // a camera without an IMU
  const auto& imu = sim_.imu();
  for (; g_ < imu.size() && (!until || ToRos(imu[g_].stamp) <= *until); ++g_) {
    sensor_msgs::Imu m;
    m.header.stamp = ToRos(imu[g_].stamp);
    m.header.frame_id = o_.imu_frame;
    const Eigen::Vector3d w = o_.R_imu_cam * imu[g_].angular_velocity;
    m.angular_velocity.x = w.x();
    m.angular_velocity.y = w.y();
    m.angular_velocity.z = w.z();
    if (g_ < sim_.accel().size()) {  // the accelerometer, same axes
      const Eigen::Vector3d a = o_.R_imu_cam * sim_.accel()[g_].linear_acceleration;
      m.linear_acceleration.x = a.x();
      m.linear_acceleration.y = a.y();
      m.linear_acceleration.z = a.z();
    }
    m.orientation_covariance[0] = -1;
    bag_->write(o_.imu_topic, m.header.stamp, m);
  }
}

Status Recorder::WriteFrame(int i, double readout_s,
                            steadiface::sim::TruthFileWriter* truth_file) {
  cv::Mat frame;
  steadiface::sim::SimTruth truth;
  const Status rendered = sim_.Render(i, &frame, &truth);
  if (!rendered.ok()) return rendered;
  const ros::Time stamp = ToRos(truth.stamp);
  // The camera's last row is captured at stamp + readout; IMU samples up
  // to then are recorded before the image.
  const ros::Time last_row = stamp + ros::Duration(readout_s);
  WriteImu(&last_row);
  cv::Mat img = frame;
  std::string enc = sensor_msgs::image_encodings::BGR8;
  if (o_.mono) {
    cv::cvtColor(frame, img, cv::COLOR_BGR2GRAY);
    enc = sensor_msgs::image_encodings::MONO8;
  }
  std_msgs::Header h;
  h.stamp = stamp;
  h.frame_id = o_.camera_frame;
  h.seq = i;
  const std::string& c = o_.compress_images;
  if (c.empty()) {
    bag_->write(o_.image_topic, last_row, cv_bridge::CvImage(h, enc, img).toImageMsg());
  } else {
    // As compressed_image_transport publishes it.
    sensor_msgs::CompressedImage m;
    m.header = h;
    m.format = enc + "; " + c + " compressed " + enc;
    cv::imencode(c == "jpeg" ? ".jpg" : ".png", img, m.data,
                 {c == "jpeg" ? cv::IMWRITE_JPEG_QUALITY : cv::IMWRITE_PNG_COMPRESSION,
                  c == "jpeg" ? 95 : 3});
    bag_->write(o_.image_topic + "/compressed", last_row, m);
  }
  if (o_.info_topic != "none") {
    bag_->write(o_.info_topic, last_row, steadiface_ros::ToCameraInfo(sim_.intrinsics(), h));
  }
  truth_file->Add(i, stamp.toSec(), truth);
  return Status::Ok();
}

// The bag (written as <out>.part, LZ4 chunks) and the truth file.
Status Record(const SimulateOptions& o, const steadiface::sim::SimulationSettings& settings,
              const steadiface::sim::SimulatorOptions& so, const steadiface::sim::Simulator& sim,
              const std::string& tmp) {
  rosbag::Bag bag;
  try {
    bag.open(tmp, rosbag::bagmode::Write);
    bag.setCompression(rosbag::compression::LZ4);
  } catch (const rosbag::BagException& e) {
    return Status::Error("cannot write " + tmp + ": " + e.what());
  }
  Recorder recorder(o, sim, &bag);
  std::ofstream csv(o.out + ".truth.csv");
  steadiface::sim::TruthFileWriter truth_file(&csv, settings);
  Status s;
  for (int i = 0; s.ok() && i < sim.num_frames(); ++i) {
    s = recorder.WriteFrame(i, so.readout_s, &truth_file);
  }
  recorder.WriteImu(nullptr);
  bag.close();
  return s;
}

}  // namespace

int RunSimulation(const SimulateOptions& o) {
  steadiface::sim::SimulationSettings settings;
  steadiface::sim::SimulatorOptions so = o.sim;
  std::unique_ptr<steadiface::sim::Simulator> sim;
  const std::string tmp = o.out + ".part";
  Status s = MakeSimulation(o, &settings, &so, &sim);
  if (s.ok()) s = Record(o, settings, so, *sim, tmp);
  if (!s.ok()) {
    std::cerr << "steadiface_simulate: " << s.message() << "\n";
    return 1;
  }
  const steadiface::CameraIntrinsics& k = sim->intrinsics();
  if (!o.calibration_out.empty()) {
    sensor_msgs::CameraInfo ci = steadiface_ros::ToCameraInfo(k, std_msgs::Header());
    if (!camera_calibration_parsers::writeCalibration(o.calibration_out, o.camera_frame, ci)) {
      std::cerr << "steadiface_simulate: cannot write " << o.calibration_out << "\n";
      return 1;
    }
  }
  if (std::rename(tmp.c_str(), o.out.c_str()) != 0) {
    std::cerr << "steadiface_simulate: cannot rename " << tmp << "\n";
    return 1;
  }
  std::cout << "wrote " << o.out << " (" << sim->num_frames() << " frames " << k.width << "x"
            << k.height << (o.mono ? " mono8" : " bgr8") << ", ";
  if (o.imu_topic == "none") {
    std::cout << "no IMU";
  } else {
    std::cout << sim->imu().size() << " IMU samples at " << so.imu_rate_hz << " Hz";
  }
  std::cout << ") and " << o.out << ".truth.csv\n";
  return 0;
}

}  // namespace steadiface_simulate
