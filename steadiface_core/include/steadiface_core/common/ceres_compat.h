#pragma once
// The one place that knows which Ceres it is built against.
//
// Ceres 2.1 (Debian 12) introduced ceres::Manifold and deprecated
// LocalParameterization (removed in 2.2); Ceres 1.14 (the ROS Noetic
// generation: Ubuntu 20.04, Debian 11) has only LocalParameterization. Both
// describe the same quaternion update for Eigen's (x, y, z, w) storage order:
//   Plus(q, delta) = [cos|delta|, sin|delta| / |delta| * delta] * q,
// so the solver steps a rotation by 2|delta| either way.

#include <ceres/problem.h>
#include <ceres/version.h>

#if CERES_VERSION_MAJOR > 2 || \
    (CERES_VERSION_MAJOR == 2 && CERES_VERSION_MINOR >= 1)
#define STEADIFACE_CERES_HAS_MANIFOLD 1
#include <ceres/manifold.h>
#else
#define STEADIFACE_CERES_HAS_MANIFOLD 0
#include <ceres/local_parameterization.h>
#endif

namespace steadiface {
namespace ceres_compat {

#if STEADIFACE_CERES_HAS_MANIFOLD
using EigenQuaternionTangent = ceres::EigenQuaternionManifold;
#else
using EigenQuaternionTangent = ceres::EigenQuaternionParameterization;
#endif

/// Adds `q` (4 doubles, Eigen order x, y, z, w) to `problem` as a unit
/// quaternion; the problem owns the manifold (or parameterization).
inline void AddQuaternionBlock(ceres::Problem* problem, double* q) {
  problem->AddParameterBlock(q, 4, new EigenQuaternionTangent);
}

/// Declares a block already in `problem` a unit quaternion (Eigen order).
inline void SetQuaternionManifold(ceres::Problem* problem, double* q) {
#if STEADIFACE_CERES_HAS_MANIFOLD
  problem->SetManifold(q, new EigenQuaternionTangent);
#else
  problem->SetParameterization(q, new EigenQuaternionTangent);
#endif
}

/// The quaternion's tangent space as the solver sees it, whichever Ceres:
/// for tests that check Jacobians through it.
class QuaternionTangentSpace {
 public:
  /// 3: the tangent dimension.
  int TangentSize() const { return 3; }
  /// x_plus_delta = Plus(x, delta); x and the result are 4-vectors.
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const {
    return impl_.Plus(x, delta, x_plus_delta);
  }
  /// d Plus(x, delta) / d delta at delta = 0: 4 x 3, row-major.
  bool PlusJacobian(const double* x, double* jacobian) const {
#if STEADIFACE_CERES_HAS_MANIFOLD
    return impl_.PlusJacobian(x, jacobian);
#else
    return impl_.ComputeJacobian(x, jacobian);
#endif
  }

 private:
  EigenQuaternionTangent impl_;
};

}  // namespace ceres_compat
}  // namespace steadiface
