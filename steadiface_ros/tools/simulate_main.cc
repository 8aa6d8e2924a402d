// steadiface_simulate: renders a simulator preset into a ROS bag
// (sensor_msgs/Image bgr8 or mono8, CameraInfo, Imu with angular velocity
// and orientation_covariance[0] = -1) plus a ground-truth CSV sidecar.
//
//   rosrun steadiface steadiface_simulate --preset walk --out walk.bag
//       [--duration 3] [--size 640x360] [--fps 30] [--imu-rate 200]
//       [--seed 1] [--mono] [--data DIR] [--clock-offset S]
#include <cstdio>
#include <iostream>
#include <string>

#include "steadiface_core/common/command_line.h"
#include "steadiface_simulate/simulate_run.h"

namespace {

std::string Usage() {
  std::string u =
      "usage: steadiface_simulate --preset NAME --out FILE.bag [--duration S]\n"
      "  [--size WxH] [--fps F] [--imu-rate HZ] [--seed N] [--mono] [--data DIR]\n"
      "  [--clock-offset S] [--readout S] [--epoch S] [--no-face] [--hfov RAD]\n"
      "  [--background FILE: the scene's photo, in --data (default building.jpg)]\n"
      "  [--image-topic T] [--info-topic T|none] [--imu-topic T|none: none, a camera\n"
      "   without an IMU]\n"
      "  [--camera-frame F] [--imu-frame F]\n"
      "  [--compress-images jpeg|png: sensor_msgs/CompressedImage on <image-topic>/compressed]\n"
      "  [--imu-rotation qx,qy,qz,qw: the IMU's mounting, R_imu_cam; the gyro is\n"
      "   recorded in IMU axes, so the stabilizer needs imu/R_cam_imu = its inverse]\n"
      "  [--calibration-out FILE.yaml: the camera's intrinsics as a camera_calibration\n"
      "   YAML, for camera_info_url]\n"
      "presets:";
  for (const std::string& p : steadiface::sim::PresetNames()) u += " " + p;
  return u + "\n";
}

void AddFlags(steadiface::CommandLine* cl, steadiface_simulate::SimulateOptions* s) {
  steadiface::sim::SimulatorOptions* o = &s->sim;
  cl->String("--preset", &s->preset).String("--out", &s->out).String("--data", &s->data);
  cl->Double("--duration", &o->duration_s).Double("--fps", &o->fps);
  cl->Double("--imu-rate", &o->imu_rate_hz).UInt64("--seed", &o->seed);
  cl->String("--background", &o->background_photo).Flag("--mono", &s->mono);
  cl->ClearFlag("--no-face", &o->render_face).Double("--clock-offset", &o->imu_clock_offset_s);
  cl->Double("--readout", &s->readout).Double("--epoch", &s->epoch).Double("--hfov", &o->hfov_rad);
  cl->String("--image-topic", &s->image_topic).String("--info-topic", &s->info_topic);
  cl->String("--imu-topic", &s->imu_topic).String("--camera-frame", &s->camera_frame);
  cl->String("--imu-frame", &s->imu_frame).String("--calibration-out", &s->calibration_out);
  cl->Value("--compress-images", "jpeg or png", [s](const std::string& v) {
    s->compress_images = v;
    return v == "jpeg" || v == "png";
  });
  cl->Value("--imu-rotation", "x,y,z,w of a rotation", [s](const std::string& v) {
    double x, y, z, w;
    if (std::sscanf(v.c_str(), "%lf,%lf,%lf,%lf", &x, &y, &z, &w) != 4) return false;
    s->R_imu_cam = Eigen::Quaterniond(w, x, y, z);
    if (!(s->R_imu_cam.norm() > 0.5)) return false;
    s->R_imu_cam.normalize();
    return true;
  });
  cl->Value("--size", "WxH", [o](const std::string& v) {
    return std::sscanf(v.c_str(), "%dx%d", &o->width, &o->height) == 2;
  });
}

}  // namespace

int main(int argc, char** argv) {
  steadiface_simulate::SimulateOptions o;
  steadiface::CommandLine cl;
  AddFlags(&cl, &o);
  int status = 0;
  if (!cl.Start(argc, argv, "steadiface_simulate", Usage(), [&o] { return !o.out.empty(); },
                std::cout, std::cerr, &status)) {
    return status;
  }
  return steadiface_simulate::RunSimulation(o);
}
