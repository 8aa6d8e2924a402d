// steadiface_simulate: renders a simulator preset into a ROS bag
// (sensor_msgs/Image bgr8 or mono8, CameraInfo, Imu with angular velocity
// and orientation_covariance[0] = -1) plus a ground-truth CSV sidecar.
//
//   rosrun steadiface steadiface_simulate --preset walk --out walk.bag
//       [--duration 3] [--size 640x360] [--fps 30] [--imu-rate 200]
//       [--seed 1] [--mono] [--data DIR] [--clock-offset S]
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

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

#include "steadiface_core/common/command_line.h"
#include "steadiface_core/sim/simulator.h"
#include "steadiface_core/sim/truth_file.h"
#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/time_conversion.h"

namespace {

int Usage() {
  std::cerr << "usage: steadiface_simulate --preset NAME --out FILE.bag [--duration S]\n"
               "  [--size WxH] [--fps F] [--imu-rate HZ] [--seed N] [--mono] [--data DIR]\n"
               "  [--clock-offset S] [--readout S] [--epoch S] [--no-face] [--hfov RAD]\n"
               "  [--background FILE: the scene's photo, in --data (default building.jpg)]\n"
               "  [--image-topic T] [--info-topic T|none] [--imu-topic T]\n"
               "  [--camera-frame F] [--imu-frame F]\n"
               "  [--compress-images jpeg|png: sensor_msgs/CompressedImage on <image-topic>/compressed]\n"
               "  [--imu-rotation qx,qy,qz,qw: the IMU's mounting, R_imu_cam; the gyro is\n"
               "   recorded in IMU axes, so the stabilizer needs imu/R_cam_imu = its inverse]\n"
               "  [--calibration-out FILE.yaml: the camera's intrinsics as a camera_calibration\n"
               "   YAML, for camera_info_url]\n"
               "presets:";
  for (const std::string& p : steadiface::sim::PresetNames()) std::cerr << " " << p;
  std::cerr << "\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  steadiface::sim::SimulatorOptions o;
  std::string preset = "walk", out, data;
  bool mono = false;
  double epoch = 1.7e9;  // bag stamps start here (a realistic ROS time)
  double readout = -1;
  std::string image_topic = "/camera/image_raw", info_topic = "/camera/camera_info",
              imu_topic = "/imu", camera_frame = "camera_optical", imu_frame = "camera_optical",
              calibration_out, compress_images;
  Eigen::Quaterniond R_imu_cam = Eigen::Quaterniond::Identity();
  steadiface::CommandLine cl;
  cl.String("--preset", &preset).String("--out", &out).String("--data", &data);
  cl.Double("--duration", &o.duration_s).Double("--fps", &o.fps);
  cl.Double("--imu-rate", &o.imu_rate_hz).UInt64("--seed", &o.seed);
  cl.String("--background", &o.background_photo).Flag("--mono", &mono);
  cl.ClearFlag("--no-face", &o.render_face).Double("--clock-offset", &o.imu_clock_offset_s);
  cl.Double("--readout", &readout).Double("--epoch", &epoch).Double("--hfov", &o.hfov_rad);
  cl.String("--image-topic", &image_topic).String("--info-topic", &info_topic);
  cl.String("--imu-topic", &imu_topic).String("--camera-frame", &camera_frame);
  cl.String("--imu-frame", &imu_frame).String("--calibration-out", &calibration_out);
  cl.Value("--compress-images", "jpeg or png", [&](const std::string& v) {
    compress_images = v;
    return v == "jpeg" || v == "png";
  });
  cl.Value("--imu-rotation", "x,y,z,w of a rotation", [&](const std::string& v) {
    double x, y, z, w;
    if (std::sscanf(v.c_str(), "%lf,%lf,%lf,%lf", &x, &y, &z, &w) != 4) return false;
    R_imu_cam = Eigen::Quaterniond(w, x, y, z);
    if (!(R_imu_cam.norm() > 0.5)) return false;
    R_imu_cam.normalize();
    return true;
  });
  cl.Value("--size", "WxH", [&](const std::string& v) {
    return std::sscanf(v.c_str(), "%dx%d", &o.width, &o.height) == 2;
  });
  std::string error;
  const steadiface::CommandLine::Result parsed = cl.Parse(argc, argv, &error);
  if (parsed == steadiface::CommandLine::Result::kHelp) {
    Usage();
    return 0;
  }
  if (parsed == steadiface::CommandLine::Result::kError) {
    std::cerr << "steadiface_simulate: " << error << "\n";
    return Usage();
  }
  if (out.empty()) return Usage();
  if (data.empty()) data = ros::package::getPath("steadiface") + "/test/data";
  // What the truth file records to rebuild this simulation (the data
  // folder absolute, so the bag can be scored from anywhere).
  steadiface::sim::SimulationSettings settings;
  settings.preset = preset;
  char* abs_data = realpath(data.c_str(), nullptr);
  settings.data_dir = abs_data ? abs_data : data;
  free(abs_data);
  settings.base = o;
  settings.readout_s = readout;
  settings.epoch_s = epoch;
  steadiface::Status s = steadiface::sim::MakeSimulatorOptions(settings, &o);
  std::unique_ptr<steadiface::sim::Simulator> sim;
  if (s.ok()) s = steadiface::sim::Simulator::Create(o, &sim);
  if (!s.ok()) {
    std::cerr << "steadiface_simulate: " << s.message() << "\n";
    return 1;
  }
  const std::string tmp = out + ".part";
  rosbag::Bag bag;
  try {
    bag.open(tmp, rosbag::bagmode::Write);
    bag.setCompression(rosbag::compression::LZ4);
  } catch (const rosbag::BagException& e) {
    std::cerr << "steadiface_simulate: cannot write " << tmp << ": " << e.what() << "\n";
    return 1;
  }
  const ros::Duration shift(epoch);
  auto to_ros = [&](steadiface::Time t) { return steadiface_ros::ToRosTime(t) + shift; };
  // IMU and frames interleaved in time order (as a recording would be).
  const auto& imu = sim->imu();
  size_t g = 0;
  const steadiface::CameraIntrinsics& k = sim->intrinsics();
  // Writes IMU samples [g, end) whose stamps are <= until (all if none).
  auto write_imu = [&](const ros::Time* until) {
    for (; g < imu.size() && (!until || to_ros(imu[g].stamp) <= *until); ++g) {
      sensor_msgs::Imu m;
      m.header.stamp = to_ros(imu[g].stamp);
      m.header.frame_id = imu_frame;
      const Eigen::Vector3d w = R_imu_cam * imu[g].angular_velocity;
      m.angular_velocity.x = w.x();
      m.angular_velocity.y = w.y();
      m.angular_velocity.z = w.z();
      if (g < sim->accel().size()) {  // the accelerometer, same axes
        const Eigen::Vector3d a = R_imu_cam * sim->accel()[g].linear_acceleration;
        m.linear_acceleration.x = a.x();
        m.linear_acceleration.y = a.y();
        m.linear_acceleration.z = a.z();
      }
      m.orientation_covariance[0] = -1;
      bag.write(imu_topic, m.header.stamp, m);
    }
  };
  std::ofstream csv(out + ".truth.csv");
  steadiface::sim::TruthFileWriter truth_file(&csv, settings);
  for (int i = 0; i < sim->num_frames(); ++i) {
    cv::Mat frame;
    steadiface::sim::SimTruth truth;
    sim->Render(i, &frame, &truth);
    const ros::Time stamp = to_ros(truth.stamp);
    // The camera's last row is captured at stamp + readout; IMU samples up
    // to then are recorded before the image.
    const ros::Time last_row = stamp + ros::Duration(o.readout_s);
    write_imu(&last_row);
    cv::Mat img = frame;
    std::string enc = sensor_msgs::image_encodings::BGR8;
    if (mono) {
      cv::cvtColor(frame, img, cv::COLOR_BGR2GRAY);
      enc = sensor_msgs::image_encodings::MONO8;
    }
    std_msgs::Header h;
    h.stamp = stamp;
    h.frame_id = camera_frame;
    h.seq = i;
    if (compress_images.empty()) {
      bag.write(image_topic, last_row, cv_bridge::CvImage(h, enc, img).toImageMsg());
    } else {
      // As compressed_image_transport publishes it.
      sensor_msgs::CompressedImage c;
      c.header = h;
      c.format = enc + "; " + compress_images + " compressed " + enc;
      cv::imencode(compress_images == "jpeg" ? ".jpg" : ".png", img, c.data,
                   {compress_images == "jpeg" ? cv::IMWRITE_JPEG_QUALITY : cv::IMWRITE_PNG_COMPRESSION,
                    compress_images == "jpeg" ? 95 : 3});
      bag.write(image_topic + "/compressed", last_row, c);
    }
    if (info_topic != "none") bag.write(info_topic, last_row, steadiface_ros::ToCameraInfo(k, h));
    truth_file.Add(i, stamp.toSec(), truth);
  }
  write_imu(nullptr);
  bag.close();
  if (!calibration_out.empty()) {
    sensor_msgs::CameraInfo ci = steadiface_ros::ToCameraInfo(k, std_msgs::Header());
    if (!camera_calibration_parsers::writeCalibration(calibration_out, camera_frame, ci)) {
      std::cerr << "steadiface_simulate: cannot write " << calibration_out << "\n";
      return 1;
    }
  }
  if (std::rename(tmp.c_str(), out.c_str()) != 0) {
    std::cerr << "steadiface_simulate: cannot rename " << tmp << "\n";
    return 1;
  }
  std::cout << "wrote " << out << " (" << sim->num_frames() << " frames " << k.width << "x"
            << k.height << (mono ? " mono8" : " bgr8") << ", " << imu.size() << " IMU samples at "
            << o.imu_rate_hz << " Hz) and " << out << ".truth.csv\n";
  return 0;
}
