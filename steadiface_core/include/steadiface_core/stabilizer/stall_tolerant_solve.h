#pragma once

#include <functional>

#include <ceres/problem.h>
#include <ceres/solver.h>

namespace steadiface {

/// ceres::Solve under `options`, except that a wall-time cap
/// (max_solver_time_in_seconds) that runs out before the first step is
/// taken as a stall, not as the solve's answer: the parameters are put
/// back by `restore` and the problem is solved again under the iteration
/// cap alone. The time cap bounds the solver's own work, but it also fires
/// when the process stalls (a loaded machine, code paged in on first use)
/// before any step, which would otherwise leave the initial parameters as
/// the result and make it depend on the machine's load. Returns whether
/// the solve was rerun.
bool StallTolerantSolve(const ceres::Solver::Options& options, ceres::Problem* problem,
                        const std::function<void()>& restore, ceres::Solver::Summary* summary);

}  // namespace steadiface
