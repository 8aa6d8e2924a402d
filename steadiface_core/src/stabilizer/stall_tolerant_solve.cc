#include "steadiface_core/stabilizer/stall_tolerant_solve.h"

namespace steadiface {

bool StallTolerantSolve(const ceres::Solver::Options& options, ceres::Problem* problem,
                        const std::function<void()>& restore, ceres::Solver::Summary* summary) {
  ceres::Solve(options, problem, summary);
  // Iteration 0 is the initial evaluation: no step was taken.
  const bool no_step = summary->iterations.size() <= 1;
  if (summary->termination_type != ceres::NO_CONVERGENCE || !no_step ||
      options.max_num_iterations <= 0) {
    return false;
  }
  if (restore) restore();
  ceres::Solver::Options uncapped = options;
  uncapped.max_solver_time_in_seconds = 1e6;
  ceres::Solve(uncapped, problem, summary);
  return true;
}

}  // namespace steadiface
