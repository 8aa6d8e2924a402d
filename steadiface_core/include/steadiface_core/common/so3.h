#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace steadiface {

/// Exponential map of SO(3): the unit quaternion of a rotation by |phi| rad
/// about phi / |phi|. Exact for any angle; uses a Taylor series near zero.
Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& phi);

/// Logarithm map: the rotation vector (axis * angle, angle in [0, pi]) of a
/// unit quaternion. Sign-invariant: q and -q give the same result.
Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q);

/// Angle between two rotations [rad], in [0, pi].
double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

/// `q` or `-q`, whichever has a non-negative dot product with `reference`
/// (the same rotation on the reference's hemisphere).
Eigen::Quaterniond AlignSign(const Eigen::Quaterniond& q,
                             const Eigen::Quaterniond& reference);

}  // namespace steadiface
