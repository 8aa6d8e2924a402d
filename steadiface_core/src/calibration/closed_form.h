#pragma once

// The calibrator's closed-form start: each frame pair's rotation from the
// video (Kabsch), the coarse clock offset from rotation magnitudes, the
// mounting from Wahba's problem; and, for the result, the nearest axis
// permutation and the plots. Private to src/calibration/.

#include <limits>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "steadiface_core/calibration/calibrator.h"
#include "steadiface_core/calibration/gyro_integral.h"
#include "steadiface_core/check/gyro_video_check.h"
#include "steadiface_core/common/percentile.h"
#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace calibration_internal {

// The rotation Q with b ~ Q a (Kabsch), unit vectors.
inline Eigen::Matrix3d Kabsch(const std::vector<Eigen::Vector3d>& a,
                       const std::vector<Eigen::Vector3d>& b,
                       const std::vector<bool>& use) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) {
    if (use[i]) H += a[i] * b[i].transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double d = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0
                       ? -1.0
                       : 1.0;
  return svd.matrixV() * Eigen::Vector3d(1, 1, d).asDiagonal() *
         svd.matrixU().transpose();
}

// One frame pair's rotation from the video: mid-row times [s since the
// gyro origin] and the camera-frame rotation, C_a^T C_b = Exp(theta).
struct VideoRotation {
  double ta, tb;
  Eigen::Vector3d theta;
};

// The gyro's rotation over a pair's times at a clock offset.
inline Eigen::Vector3d GyroTheta(const GyroIntegral& g, const VideoRotation& v, double offset) {
  return g.At(v.tb - offset) - g.At(v.ta - offset);
}

// The gyro's mean angular speed over [begin, end] (every 10 ms).
inline double MeanAngularSpeed(const GyroIntegral& g, double begin, double end, double offset) {
  double sum = 0.0;
  int n = 0;
  for (double t = begin; t <= end; t += 0.01, ++n) sum += g.Rate(t - offset).norm();
  return n ? sum / n : 0.0;
}

// Kabsch on each pair's rays, one outlier pass (3x the median error).
// `rel` maps a stamp to seconds since the gyro origin; `mid` moves it to
// the middle row.
template <typename PairT, typename Rel>
std::vector<VideoRotation> VideoRotations(const std::vector<const PairT*>& good,
                                          const CameraIntrinsics& k, double mid, const Rel& rel) {
  std::vector<VideoRotation> video;
  for (const PairT* p : good) {
    const size_t n = p->ray_a.size();
    std::vector<Eigen::Vector3d> a(n), b(n);
    for (size_t i = 0; i < n; ++i) {
      a[i] = p->ray_a[i].normalized();
      b[i] = Eigen::Vector3d((p->px_b[i].x() - k.cx) / k.fx, (p->px_b[i].y() - k.cy) / k.fy, 1.0)
                 .normalized();
    }
    std::vector<bool> use(n, true);
    Eigen::Matrix3d Q = Kabsch(a, b, use);
    std::vector<double> err(n);
    for (size_t i = 0; i < n; ++i) err[i] = (Q * a[i] - b[i]).norm();
    const double cut = 3.0 * Percentile(err, 0.5) + 1e-9;
    for (size_t i = 0; i < n; ++i) use[i] = err[i] <= cut;
    Q = Kabsch(a, b, use);
    video.push_back({rel(p->a) + mid, rel(p->b) + mid, -LogSO3(Eigen::Quaterniond(Q))});
  }
  return video;
}

// The offset whose gyro rotation magnitudes best match the video's (free of
// the mounting), searched in steps over +-range around `initial`.
inline double CoarseOffset(const std::vector<VideoRotation>& video, const GyroIntegral& g,
                    double initial, double range, double step) {
  double best = std::numeric_limits<double>::infinity(), offset_best = initial;
  for (double d = -range; d <= range + 1e-12; d += step) {
    const double offset = initial + d;
    double cost = 0.0;
    for (const VideoRotation& v : video) {
      const double e = v.theta.norm() - GyroTheta(g, v, offset).norm();
      cost += e * e;
    }
    if (cost < best) {
      best = cost;
      offset_best = offset;
    }
  }
  return offset_best;
}

// Wahba's problem: the rotation R with theta_video ~ R theta_gyro.
inline Eigen::Matrix3d WahbaRotation(const std::vector<VideoRotation>& video, const GyroIntegral& g,
                              double offset) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (const VideoRotation& v : video) B += v.theta * GyroTheta(g, v, offset).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double d = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * Eigen::Vector3d(1, 1, d).asDiagonal() * svd.matrixV().transpose();
}

// The signed axis permutation nearest to the estimated mounting.
inline void NearestPermutation(CalibrationResult* res) {
  double best_angle = 1e9;
  for (const Eigen::Quaterniond& P : GyroVideoCheck::SignedAxisPermutations()) {
    const double a = res->R_cam_imu.angularDistance(P);
    if (a < best_angle) {
      best_angle = a;
      res->nearest_permutation = P;
    }
  }
  res->misalignment_deg = best_angle * 180.0 / M_PI;
}

// Plots: angular speed from the video and from the gyro, before (initial
// offset, no bias) and after.
inline void AddPlots(const std::vector<VideoRotation>& video, const GyroIntegral& g, double t0,
              double initial_offset_s, CalibrationResult* res) {
  for (const VideoRotation& v : video) {
    const double dt = v.tb - v.ta;
    res->plot_t.push_back(0.5 * (v.ta + v.tb) - t0);
    res->plot_video.push_back(v.theta.norm() / dt);
    res->plot_gyro_before.push_back(GyroTheta(g, v, initial_offset_s).norm() / dt);
    res->plot_gyro_after.push_back((GyroTheta(g, v, res->time_offset_s) - res->bias * dt).norm() /
                                   dt);
  }
}

}  // namespace calibration_internal
}  // namespace steadiface
