// The stabilizer's per-frame solve (paper Eq. 5): the residual blocks of
// each term, the Ceres solve and the terms' energies at the final pose.
#include <cmath>
#include <vector>

#include <ceres/problem.h>
#include <ceres/solver.h>

#include "steadiface_core/common/ceres_compat.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/stabilizer/distortion_cost.h"
#include "steadiface_core/stabilizer/fitting_cost.h"
#include "steadiface_core/stabilizer/following_cost.h"
#include "steadiface_core/stabilizer/horizon_cost.h"
#include "steadiface_core/stabilizer/protrusion_cost.h"
#include "steadiface_core/stabilizer/rotation_smoothness_cost.h"
#include "steadiface_core/stabilizer/stabilizer.h"
#include "steadiface_core/stabilizer/stall_tolerant_solve.h"
#include "steadiface_core/stabilizer/translation_smoothness_cost.h"
#include "stabilizer/pose_problem.h"

namespace steadiface {
namespace {

using stabilizer_internal::Clock;
using stabilizer_internal::MsSince;

// Sum of squared residuals of a set of blocks (= w * E for that term).
double TermEnergy(ceres::Problem* problem,
                  const std::vector<ceres::ResidualBlockId>& blocks) {
  if (blocks.empty()) return 0.0;
  ceres::Problem::EvaluateOptions eo;
  eo.residual_blocks = blocks;
  eo.apply_loss_function = false;
  double cost = 0.0;
  if (!problem->Evaluate(eo, &cost, nullptr, nullptr, nullptr)) return NAN;
  return 2.0 * cost;
}

}  // namespace

void Stabilizer::SolveStep(Time stamp, const OrientationTimeline& timeline,
                           const RowTiming& timing, const LayerState& layer,
                           const FaceObservation* fit_face, const StabilizerWeights& w,
                           double dt, PoseProblem* pp, Eigen::Quaterniond* R_v,
                           Eigen::Vector2d* t, StabilizerFrame* f, StabilizerStats* stats) {
  // Solve (Eq. 5) from the initial pose in *R_v, *t.
  const auto t_solve = Clock::now();
  const Eigen::Quaterniond R_v0 = *R_v;
  const Eigen::Vector2d t0 = *t;
  pp->q() = R_v0.coeffs();
  pp->t() = t0;
  ceres_compat::AddQuaternionBlock(&pp->problem, pp->q_block);
  pp->problem.AddParameterBlock(pp->t_block, 2);
  AddFitTerms(fit_face, w, *f, pp);
  AddRotationTerms(stamp, timeline, timing, layer, w, dt, *f, pp);
  AddOffsetTerms(layer, w, R_v0, t0, *f, pp);
  RunSolve(R_v0, t0, pp, R_v, t, f, stats);
  f->solver.time_ms = MsSince(t_solve);
  f->timings.solve_ms = f->solver.time_ms;
}

void Stabilizer::AddFitTerms(const FaceObservation* fit_face, const StabilizerWeights& w,
                             const StabilizerFrame& frame, PoseProblem* pp) const {
  // E_f (Eq. 6), one block per landmark, each through its own row.
  const StabilizerFrame* f = &frame;
  ceres::Problem& problem = pp->problem;
  const double f_r = model_.real_focal(), f_v = model_.virtual_focal();
  if (f->has_target && w.fit > 0.0) {
    const FaceObservation* face = fit_face;
    const double s = std::sqrt(w.fit / face->landmarks.size());
    for (size_t i = 0; i < face->landmarks.size(); ++i) {
      const Eigen::Quaterniond R_row =
          face->landmark_rows.empty()
              ? f->R_r
              : AlignSign(f->rows.At(face->landmark_rows[i]), f->R_r);
      pp->b_fit.push_back(problem.AddResidualBlock(
          FittingCost::Create(face->landmarks[i], R_row, f->H, f_r, f_v, s),
          nullptr, pp->q_block, pp->t_block));
    }
  }
}

void Stabilizer::AddRotationTerms(Time stamp, const OrientationTimeline& timeline,
                                  const RowTiming& timing, const LayerState& layer,
                                  const StabilizerWeights& w, double dt,
                                  const StabilizerFrame& frame, PoseProblem* pp) const {
  // E_d (Eq. 7), E_o (Eq. 8) and E_r (Eq. 9); E_h (the level horizon).
  const StabilizerFrame* f = &frame;
  ceres::Problem& problem = pp->problem;
  const Eigen::Quaterniond R_ref = HorizonReference(f->R_r);
  if (horizon_.active && horizon_.weight > 0.0) {
    pp->b_horizon.push_back(problem.AddResidualBlock(
        HorizonCost::Create(horizon_.up_world, std::sqrt(horizon_.weight),
                            std::sin(horizon_.tolerance_rad)),
        nullptr,
        pp->q_block));
  }
  if (w.distortion > 0.0) {
    pp->b_dist.push_back(problem.AddResidualBlock(
        DistortionCost::Create(R_ref, options_.terms.distortion_threshold_rad,
                               options_.terms.distortion_slope,
                               std::sqrt(w.distortion)),
        nullptr, pp->q_block));
  }
  if (w.follow > 0.0) {
    pp->b_follow.push_back(problem.AddResidualBlock(
        FollowingCost::Create(R_ref, std::sqrt(w.follow)), nullptr, pp->q_block));
  }
  if (layer.history >= 1) {
    const Eigen::Quaterniond prev_delta =
        (layer.R_v_prev * layer.R_v_prev_prev.conjugate()).normalized();
    Eigen::Quaterniond c0_target = layer.R_v_prev;
    if (options_.intentional_window_s > 0.0) {
      // The real camera's mean rotation per frame over the window.
      const double W = options_.intentional_window_s;
      Eigen::Quaterniond R_old;
      if (QuerySucceeded(timeline.RealRotation(
              timing.RowTime(stamp, 0.5 * (timing.height() - 1)) - FromSeconds(W),
              &R_old))) {
        const Eigen::Vector3d rate = LogSO3(f->R_r * R_old.conjugate()) / W;
        c0_target = (ExpSO3(rate * dt) * layer.R_v_prev).normalized();
      }
    }
    pp->b_rot.push_back(problem.AddResidualBlock(
        RotationSmoothnessCost::Create(c0_target, layer.R_v_prev, prev_delta,
                                       layer.history >= 2, std::sqrt(w.rotation_c0),
                                       std::sqrt(w.rotation_c1)),
        nullptr, pp->q_block));
  }
}

void Stabilizer::AddOffsetTerms(const LayerState& layer, const StabilizerWeights& w,
                                const Eigen::Quaterniond& R_v0, const Eigen::Vector2d& t0,
                                const StabilizerFrame& frame, PoseProblem* pp) {
  // E_t (Eq. 10) and E_p (Eq. 11, at the initial pose's rows).
  const StabilizerFrame* f = &frame;
  ceres::Problem& problem = pp->problem;
  // On the first frame the offset's only prior is C0 towards 0.
  pp->b_trans.push_back(problem.AddResidualBlock(
      TranslationSmoothnessCost::Create(
          layer.history >= 1 ? layer.t_prev : Eigen::Vector2d::Zero(), layer.t_prev_prev,
          layer.history >= 2, std::sqrt(w.translation_c0),
          std::sqrt(w.translation_c1)),
      nullptr, pp->t_block));
  const double shrink_px =
      options_.terms.protrusion_shrink * model_.intrinsics().width;
  if (w.protrusion > 0.0) {
    const ProtrusionReport at_init =
        protrusion_.Check(R_v0, t0, f->rows, shrink_px);
    std::vector<Eigen::Quaterniond> R_samples;
    R_samples.reserve(at_init.rows.size());
    for (double y : at_init.rows) R_samples.push_back(f->rows.At(y));
    // The face's tolerance only where E_f holds a face this solve (AddFitTerms
    // ran first): w_f alone stays above 0 while it fades after a loss.
    const double fitted = pp->b_fit.empty() ? 0.0 : w.fit;
    pp->protrusion_alpha = ProtrusionAlpha(options_.terms, fitted, options_.weights.fit);
    pp->b_prot.push_back(problem.AddResidualBlock(
        ProtrusionCost::Create(&protrusion_, std::move(R_samples), shrink_px,
                               pp->protrusion_alpha, w.protrusion),
        nullptr, pp->q_block, pp->t_block));
  }

}

void Stabilizer::RunSolve(const Eigen::Quaterniond& R_v0, const Eigen::Vector2d& t0,
                          PoseProblem* pp, Eigen::Quaterniond* R_v, Eigen::Vector2d* t,
                          StabilizerFrame* f, StabilizerStats* stats) const {
  ceres::Problem& problem = pp->problem;
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options_.solver.max_iterations;
  so.function_tolerance = options_.solver.function_tolerance;
  so.gradient_tolerance = options_.solver.gradient_tolerance;
  so.max_solver_time_in_seconds = options_.solver.max_time_s;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  // A time cap that runs out before the first step (a stall) would leave the
  // initial pose, the previous warp with this frame's shake in it: the
  // solve is then rerun under the iteration cap alone.
  if (StallTolerantSolve(so, &problem,
                         [&] {
                           pp->q() = R_v0.coeffs();
                           pp->t() = t0;
                         },
                         &summary)) {
    f->solver.restarted = true;
    ++stats->solver_restarts;
  }
  f->solver.ran = true;
  f->solver.protrusion_alpha = pp->protrusion_alpha;
  f->solver.iterations = static_cast<int>(summary.iterations.size()) - 1;
  f->solver.termination = ceres::TerminationTypeToString(summary.termination_type);
  f->solver.initial_cost = summary.initial_cost;
  f->solver.final_cost = summary.final_cost;
  const Eigen::Quaterniond q_sol(pp->q_block[3], pp->q_block[0], pp->q_block[1],
                                 pp->q_block[2]);
  const Eigen::Vector2d t_sol = pp->t();
  f->solver.usable = summary.IsSolutionUsable() && q_sol.coeffs().allFinite() &&
                     t_sol.allFinite() && std::isfinite(summary.final_cost);
  if (f->solver.usable) {
    *R_v = q_sol.normalized();
    *t = t_sol;
  } else {
    f->flags.solver_failed = true;
    ++stats->solver_failures;
  }
}

void Stabilizer::EnergiesStep(const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                              PoseProblem* pp, StabilizerFrame* f) const {
  // Energies at the final pose.
  pp->q() = R_v.coeffs();
  pp->t() = t;
  f->energies.fit = TermEnergy(&pp->problem, pp->b_fit);
  f->energies.distortion = TermEnergy(&pp->problem, pp->b_dist);
  f->energies.follow = TermEnergy(&pp->problem, pp->b_follow);
  f->energies.rotation = TermEnergy(&pp->problem, pp->b_rot);
  f->energies.translation = TermEnergy(&pp->problem, pp->b_trans);
  f->energies.protrusion = TermEnergy(&pp->problem, pp->b_prot);
  f->energies.horizon = TermEnergy(&pp->problem, pp->b_horizon);
}

Eigen::Quaterniond Stabilizer::HorizonReference(const Eigen::Quaterniond& R_r) const {
  // lock: the real camera turned about its optical axis until gravity's up
  // is the image's up (HorizonRoll 0), for E_d and E_o to measure against.
  if (!horizon_.active || !horizon_.level_reference) return R_r;
  const Eigen::Vector3d u = R_r * horizon_.up_world;
  if (u.head<2>().norm() < 1e-3) return R_r;
  const double roll = std::atan2(u.x(), -u.y());
  return AlignSign((Eigen::AngleAxisd(-roll, Eigen::Vector3d::UnitZ()) * R_r).normalized(), R_r);
}

}  // namespace steadiface
