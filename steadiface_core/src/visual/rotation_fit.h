#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace steadiface {
namespace visual {

/// The camera's angular velocity across a pair of frames, varying linearly
/// in time: omega(t) = omega_c + alpha (t - t_c) [rad/s, rad/s^2].
using Motion = Eigen::Matrix<double, 6, 1>;  // (omega_c, alpha)

/// A feature seen in two frames: its undistorted bearing (x, y, 1) in the
/// first and its ray (x, y) in the second. Between the rows it was seen on,
/// at t1 and t2, the camera turned by Exp(phi), phi = c omega_c + d alpha,
/// with c = t2 - t1 and d = ((t2 - t_c)^2 - (t1 - t_c)^2) / 2 [s, s^2]
/// (rolling shutter: every feature has its own).
struct BearingPair {
  Eigen::Vector3d b1;
  Eigen::Vector2d n2;
  double c = 0.0;
  double d = 0.0;
};

/// Where the scene point lands in the second frame: Exp(-phi) b1 (the scene
/// stands still; the camera turns by Exp(phi)).
Eigen::Vector2d Predict(const Motion& m, const BearingPair& p);

struct RotationFit {
  Motion motion = Motion::Zero();
  std::vector<int> inliers;  // indices into the pairs
  double rms_px = 0.0;       // inliers' reprojection error
};

/// RANSAC over triples of features (each triple's motion by Gauss-Newton
/// from rest, the hypothesis with the most features within `threshold_px`
/// kept), then Gauss-Newton on the inliers, twice. `alpha_weight` weighs a
/// prior alpha_weight |alpha|^2 against the squared normalized residuals:
/// alpha is seen only through the rows' spread in time, weakly, and
/// without the prior it fits the features' noise. `focal_px` turns normalized
/// residuals into pixels. Deterministic for a given `seed`. False with
/// fewer than three pairs.
bool FitMotion(const std::vector<BearingPair>& pairs, double focal_px,
               double threshold_px, int iterations, double alpha_weight,
               uint64_t seed, RotationFit* fit);

}  // namespace visual
}  // namespace steadiface
