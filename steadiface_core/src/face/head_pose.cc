#include "steadiface_core/face/head_pose.h"

#include <cmath>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>

#include "steadiface_core/face/generic_face.h"
#include "steadiface_core/face/landmarks68.h"

namespace steadiface {

std::vector<Eigen::Vector3d> BuildHeadModel(
    const std::vector<Eigen::Vector2d>& mean_shape) {
  const auto& generic = GenericFace68();
  if (mean_shape.size() != generic.size()) return generic;
  Eigen::Vector2d eyes = Eigen::Vector2d::Zero();
  namespace l68 = landmarks68;
  for (int i = l68::kRightEyeFirst; i <= l68::kLeftEyeLast; ++i) eyes += mean_shape[i];
  eyes /= 12.0;
  const double jaw = (mean_shape[l68::kJawLeftEnd] - mean_shape[l68::kJawRightEnd]).norm();
  const double s = jaw > 1e-9 ? 0.14 / jaw : 1.0;
  std::vector<Eigen::Vector3d> out(generic.size());
  for (size_t i = 0; i < generic.size(); ++i) {
    const Eigen::Vector2d xy = s * (mean_shape[i] - eyes);
    out[i] = Eigen::Vector3d(xy.x(), xy.y(), generic[i].z());
  }
  return out;
}

bool EstimateHeadPose(const std::vector<Eigen::Vector3d>& model,
                      const std::vector<Eigen::Vector2d>& landmarks_px,
                      const CameraIntrinsics& k, double* yaw, double* pitch,
                      double* roll) {
  if (landmarks_px.size() != model.size()) return false;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  // Rigid points only: brows, nose, eyes, mouth corners and the outer jaw
  // (the jaw line and lips deform too much).
  static const int kRigid[] = {0,  2,  4,  8,  12, 14, 16, 17, 19, 21, 22, 24,
                               26, 27, 28, 29, 30, 31, 33, 35, 36, 39, 42, 45,
                               48, 54};
  for (int i : kRigid) {
    object.emplace_back(model[i].x(), model[i].y(), model[i].z());
    image.emplace_back(landmarks_px[i].x(), landmarks_px[i].y());
  }
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  cv::Vec3d rvec, tvec;
  // Start facing the camera at a plausible distance.
  const double w = std::abs(landmarks_px[landmarks68::kJawLeftEnd].x() -
                            landmarks_px[landmarks68::kJawRightEnd].x());
  tvec = cv::Vec3d(0, 0, w > 1 ? k.fx * 0.14 / w : 0.5);
  rvec = cv::Vec3d(0, 0, 0);
  bool ok = false;
  try {
    ok = cv::solvePnP(object, image, K, cv::noArray(), rvec, tvec, true,
                      cv::SOLVEPNP_ITERATIVE);
  } catch (const cv::Exception&) {
    return false;
  }
  if (!ok) return false;
  cv::Matx33d R_cam;
  cv::Rodrigues(rvec, R_cam);
  // Relative to the line of sight: a face looking straight at the camera has
  // zero pose wherever it sits in the image.
  const Eigen::Vector3d ray = Eigen::Vector3d(tvec[0], tvec[1], tvec[2]).normalized();
  if (!ray.allFinite() || ray.z() <= 0.0) return false;
  const Eigen::Matrix3d R_ray =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray).toRotationMatrix();
  Eigen::Matrix3d Rc;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) Rc(i, j) = R_cam(i, j);
  }
  const Eigen::Matrix3d R = R_ray.transpose() * Rc;
  // R = Ry(yaw) Rx(pitch) Rz(roll) (head -> camera).
  const double p = std::asin(std::max(-1.0, std::min(1.0, -R(1, 2))));
  const double y = std::atan2(R(0, 2), R(2, 2));
  const double r = std::atan2(R(1, 0), R(1, 1));
  if (!std::isfinite(p) || !std::isfinite(y) || !std::isfinite(r)) return false;
  *yaw = y;
  *pitch = p;
  *roll = r;
  return true;
}

}  // namespace steadiface
