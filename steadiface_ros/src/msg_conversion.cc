#include "steadiface_ros/msg_conversion.h"

#include <cmath>
#include <sstream>

#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {

steadiface::Status ToCameraIntrinsics(const sensor_msgs::CameraInfo& info,
                                      steadiface::CameraIntrinsics* out) {
  using steadiface::DistortionModel;
  using steadiface::Status;
  std::ostringstream err;
  if (info.K[0] == 0.0 && info.K[4] == 0.0) {
    return Status::Error(
        "camera_info: K is all zero (uncalibrated camera); calibrate it or "
        "publish a camera_info with fx, fy, cx, cy");
  }
  steadiface::CameraIntrinsics k;
  const int bx = info.binning_x > 1 ? static_cast<int>(info.binning_x) : 1;
  const int by = info.binning_y > 1 ? static_cast<int>(info.binning_y) : 1;
  const bool roi = info.roi.width > 0 && info.roi.height > 0 &&
                   (info.roi.width != info.width ||
                    info.roi.height != info.height);
  const double full_w = roi ? info.roi.width : info.width;
  const double full_h = roi ? info.roi.height : info.height;
  const double ox = roi ? info.roi.x_offset : 0.0;
  const double oy = roi ? info.roi.y_offset : 0.0;
  k.width = static_cast<int>(full_w) / bx;
  k.height = static_cast<int>(full_h) / by;
  k.fx = info.K[0] / bx;
  k.fy = info.K[4] / by;
  k.cx = (info.K[2] - ox) / bx;
  k.cy = (info.K[5] - oy) / by;

  const std::string& model = info.distortion_model;
  bool all_zero = true;
  for (double d : info.D) all_zero = all_zero && d == 0.0;
  if (info.D.empty() || all_zero) {
    k.distortion = DistortionModel::kNone;
  } else if (model == "plumb_bob" || model == "rational_polynomial") {
    k.distortion = DistortionModel::kPlumbBob;
    k.distortion_coeffs = info.D;
  } else if (model == "equidistant" || model == "fisheye") {
    k.distortion = DistortionModel::kEquidistant;
    k.distortion_coeffs = info.D;
  } else {
    err << "camera_info: unsupported distortion_model '" << model
        << "' with non-zero D (supported: plumb_bob, rational_polynomial, "
           "equidistant)";
    return Status::Error(err.str());
  }
  Status s = steadiface::ValidateIntrinsics(k);
  if (!s.ok()) return s;
  *out = k;
  return Status::Ok();
}

steadiface::GyroSample ToGyroSample(const sensor_msgs::Imu& imu) {
  steadiface::GyroSample s;
  s.stamp = ToCoreTime(imu.header.stamp);
  s.angular_velocity = Eigen::Vector3d(
      imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z);
  return s;
}

bool ToEigen(const geometry_msgs::Quaternion& msg, Eigen::Quaterniond* q) {
  Eigen::Quaterniond e(msg.w, msg.x, msg.y, msg.z);
  const double n = e.norm();
  if (!std::isfinite(n) || n < 1e-9) return false;
  *q = Eigen::Quaterniond(e.coeffs() / n);
  return true;
}

geometry_msgs::Quaternion ToMsg(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion m;
  m.w = q.w();
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  return m;
}

geometry_msgs::Transform ToTransformMsg(const Eigen::Quaterniond& q) {
  geometry_msgs::Transform t;
  t.rotation = ToMsg(q);
  return t;
}

}  // namespace steadiface_ros
