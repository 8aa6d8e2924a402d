#pragma once
// Private to the stabilizer's sources (stabilizer.cc, stabilizer_solve.cc):
// one frame's Eq. 5 problem, and their stage timer.

#include <chrono>
#include <vector>

#include <Eigen/Core>
#include <ceres/problem.h>

#include "steadiface_core/common/stopwatch.h"
#include "steadiface_core/stabilizer/stabilizer.h"

namespace steadiface {

// One frame's Eq. 5 problem: the parameter blocks and each term's residual
// blocks, kept after the solve to evaluate the energies at the final pose.
struct Stabilizer::PoseProblem {
  double q_block[4];
  double t_block[2];
  ceres::Problem problem;
  std::vector<ceres::ResidualBlockId> b_fit, b_dist, b_follow, b_rot, b_trans, b_prot,
      b_horizon;
  double protrusion_alpha = 0.0;  ///< E_p's tolerance this solve used
  Eigen::Map<Eigen::Vector4d> q() { return Eigen::Map<Eigen::Vector4d>(q_block); }
  Eigen::Map<Eigen::Vector2d> t() { return Eigen::Map<Eigen::Vector2d>(t_block); }
};

namespace stabilizer_internal {

using Clock = std::chrono::steady_clock;

using ::steadiface::MsSince;

}  // namespace stabilizer_internal
}  // namespace steadiface
