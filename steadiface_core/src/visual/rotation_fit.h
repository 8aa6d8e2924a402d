#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace steadiface {
namespace visual {

/// The camera's angular velocity across a pair of frames, varying
/// quadratically in time: omega(t) = omega_c + alpha u + beta u^2 / 2 with
/// u = t - t_c [rad/s, rad/s^2, rad/s^3].
using Motion = Eigen::Matrix<double, 9, 1>;  // (omega_c, alpha, beta)

/// A feature seen in two frames: its undistorted bearing (x, y, 1) in the
/// first and its ray (x, y) in the second. Between the rows it was seen on,
/// at u1 and u2 (t - t_c), the camera turned by Exp(phi),
/// phi = c omega_c + d alpha + e beta, with c = u2 - u1,
/// d = (u2^2 - u1^2) / 2 and e = (u2^3 - u1^3) / 6 [s, s^2, s^3] (rolling
/// shutter: every feature has its own).
struct BearingPair {
  Eigen::Vector3d b1;
  Eigen::Vector2d n2;
  double c = 0.0;
  double d = 0.0;
  double e = 0.0;
};

/// The priors that keep what the rows' spread in time sees only weakly
/// from fitting the features' noise: alpha |alpha|^2 + beta |beta|^2 added
/// to the squared normalized residuals.
struct MotionPrior {
  double alpha = 0.0;
  double beta = 0.0;
};

/// The camera's turn between the rows the pair was seen on, phi = c omega_c
/// + d alpha + e beta (a rotation vector in the camera) [rad].
Eigen::Vector3d PairTurn(const Motion& m, const BearingPair& p);

/// Where the scene point lands in the second frame: Exp(-phi) b1 (the scene
/// stands still; the camera turns by Exp(phi)).
Eigen::Vector2d Predict(const Motion& m, const BearingPair& p);

struct RotationFit {
  Motion motion = Motion::Zero();
  std::vector<int> inliers;  // indices into the pairs
  double rms_px = 0.0;       // inliers' reprojection error
  double support = 0.0;      // the inliers' share of the summed weight
  /// The standard error of the camera's turn across one pair, in its worst
  /// direction, from the inliers' spread and residual [px at the focal
  /// length]: how far the fit alone may be off.
  double turn_sigma_px = 0.0;
};

/// RANSAC over triples of features (each triple's motion by Gauss-Newton
/// from rest, the hypothesis with the most features within `threshold_px`
/// kept), then Gauss-Newton on the inliers, twice, with the `prior`.
/// A hypothesis is scored by its inliers' summed `weights` (one per pair;
/// empty: 1 each), so that features long known to move with the scene
/// outvote fresh ones on a passer-by, and the Gauss-Newton weighs each
/// inlier's residual by its weight too, so that fresh features on a near
/// object, which fit the rotation to within the threshold, pull the
/// rotation less. The weights are not scaled: a set of long-known features
/// leans on the prior less than a fresh set does. `focal_px` turns
/// normalized residuals into pixels. Deterministic for a given `seed`.
/// False with fewer than three pairs.
bool FitMotion(const std::vector<BearingPair>& pairs, const std::vector<double>& weights,
               double focal_px, double threshold_px, int iterations, const MotionPrior& prior,
               uint64_t seed, RotationFit* fit);

}  // namespace visual
}  // namespace steadiface
