#include "steadiface_core/stabilizer/stabilizer.h"

#include <chrono>
#include <cmath>
#include <sstream>
#include <vector>

#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "steadiface_core/so3.h"
#include "steadiface_core/stabilizer/distortion_cost.h"
#include "steadiface_core/stabilizer/fitting_cost.h"
#include "steadiface_core/stabilizer/following_cost.h"
#include "steadiface_core/stabilizer/protrusion_cost.h"
#include "steadiface_core/stabilizer/rotation_smoothness_cost.h"
#include "steadiface_core/stabilizer/translation_smoothness_cost.h"

namespace steadiface {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start)
      .count();
}

bool FaceUsable(const FaceObservation* face, const StabilizerOptions& o) {
  if (o.gyro_only || face == nullptr || !face->valid ||
      face->landmarks.empty() || face->confidence < o.min_face_confidence) {
    return false;
  }
  if (!face->centre.allFinite() || !std::isfinite(face->scale)) return false;
  for (const auto& p : face->landmarks) {
    if (!p.allFinite()) return false;
  }
  if (!face->landmark_rows.empty() &&
      face->landmark_rows.size() != face->landmarks.size()) {
    return false;
  }
  for (double y : face->landmark_rows) {
    if (!std::isfinite(y)) return false;
  }
  return true;
}

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

Status Stabilizer::Create(const CameraModel& model,
                          const OutputOptions& output,
                          const StabilizerOptions& options,
                          std::unique_ptr<Stabilizer>* out) {
  Status s = ValidateStabilizerOptions(options);
  if (!s.ok()) return s;
  OutputGeometry geometry;
  s = OutputGeometry::Create(model, output, &geometry);
  if (!s.ok()) return s;
  out->reset(new Stabilizer(model, geometry, options));
  return Status::Ok();
}

Stabilizer::Stabilizer(const CameraModel& model, const OutputGeometry& output,
                       const StabilizerOptions& options)
    : model_(model),
      output_(output),
      protrusion_(model, output, options.terms.protrusion_samples_per_edge),
      options_(options),
      smoother_(options.head),
      dynamic_(options.dynamic) {}

Status Stabilizer::UpdateOptions(const StabilizerOptions& options) {
  Status s = ValidateStabilizerOptions(options);
  if (!s.ok()) return s;
  if (options.terms.protrusion_samples_per_edge !=
      options_.terms.protrusion_samples_per_edge) {
    return Status::Error(
        "terms.protrusion_samples_per_edge cannot change at run time");
  }
  options_ = options;
  smoother_ = HeadSmoother(options.head);
  dynamic_.set_options(options.dynamic);
  return Status::Ok();
}

void Stabilizer::reset() {
  history_ = 0;
  has_H_ = false;
  has_held_face_ = false;
  dynamic_.reset();
  ++stats_.resets;
}

Status Stabilizer::Process(Time stamp, const OrientationTimeline& timeline,
                           const RowTiming& timing,
                           const FaceObservation* face,
                           StabilizerFrame* frame) {
  const auto start = Clock::now();
  if (history_ > 0 && stamp <= last_stamp_) {
    std::ostringstream err;
    err << "frame stamp " << ToSeconds(stamp)
        << " s is not after the previous one (" << ToSeconds(last_stamp_)
        << " s); reset() the stabilizer after a time jump";
    return Status::Error(err.str());
  }
  if (timing.height() != model_.intrinsics().height) {
    return Status::Error("row timing is for another image height");
  }
  StabilizerFrame f;
  f.stamp = stamp;
  const QueryResult q = RowRotations::Build(
      timeline, timing, stamp, options_.row_rotation_samples, &f.rows);
  if (!QuerySucceeded(q)) {
    ++stats_.no_gyro_frames;
    return Status::Error(
        "gyro does not cover the frame's rows (first row " +
        std::to_string(ToSeconds(timing.FirstRowTime(stamp))) + " s, last row " +
        std::to_string(ToSeconds(timing.LastRowTime(stamp))) + " s)");
  }
  f.R_r = f.rows.Middle();
  if (history_ > 0) f.R_r = AlignSign(f.R_r, R_r_prev_);
  const double dt = history_ > 0 ? ToSeconds(stamp - last_stamp_) : 0.0;
  f.flags.first_frame = history_ == 0;

  // Dynamic weights (§4.4).
  const auto t_weights = Clock::now();
  const bool use_face = FaceUsable(face, options_);
  double mean_speed = -1.0;
  if (!timeline.MeanAngularSpeed(
          stamp - FromSeconds(options_.dynamic.gyro_window_s), stamp,
          &mean_speed)) {
    mean_speed = -1.0;
  }
  // A camera fixed in the world at the epoch's first real rotation: what
  // it sees does not depend on where the gyro integration started.
  if (history_ == 0) R_reference_ = f.R_r;
  Eigen::Vector2d stabilized_centre = Eigen::Vector2d::Zero();
  if (use_face) {
    model_.Project(face->centre, R_reference_, Eigen::Vector2d::Zero(), f.R_r,
                   &stabilized_centre);
  }
  f.factors =
      dynamic_.Update(dt, mean_speed, use_face ? face : nullptr,
                      stabilized_centre);
  StabilizerWeights w = options_.weights;
  w.fit = options_.gyro_only ? 0.0 : w.fit * f.factors.fit;
  w.rotation_c0 *= f.factors.smoothness;
  w.rotation_c1 *= f.factors.smoothness;
  w.translation_c0 *= f.factors.smoothness;
  w.translation_c1 *= f.factors.smoothness;
  f.weights = w;
  f.timings.weights_ms = MsSince(t_weights);

  // Initial pose (paper Eq. 12): identity-equivalent (virtual = real) on the
  // first frame, then the real rotation change applied to the previous
  // virtual rotation, and the previous offset.
  Eigen::Quaterniond R_v0 = f.R_r;
  Eigen::Vector2d t0 = Eigen::Vector2d::Zero();
  if (history_ > 0) {
    R_v0 = AlignSign(((f.R_r * R_r_prev_.conjugate()) * R_v_prev_).normalized(),
                     R_v_prev_);
    t0 = t_prev_;
  }

  // The face the fitting term uses: this frame's, or while w_f fades out
  // after a loss, the last one held fixed in the world.
  const FaceObservation* fit_face = use_face ? face : nullptr;
  FaceObservation held;
  if (!use_face && has_held_face_ && has_H_ && w.fit > 1e-3 * options_.weights.fit) {
    held = held_face_;
    bool ok = true;
    for (size_t i = 0; i < held.landmarks.size() && ok; ++i) {
      const Eigen::Quaterniond R_row =
          held.landmark_rows.empty() ? f.R_r : f.rows.At(held.landmark_rows[i]);
      ok = model_.Unproject(held_face_.landmarks[i], R_reference_, Eigen::Vector2d::Zero(),
                            R_row, &held.landmarks[i]);
    }
    if (ok) {
      ComputeCentreAndScale(&held);
      fit_face = &held;
      f.flags.held_face = true;
    }
  }
  if (fit_face == nullptr) has_held_face_ = false;

  // Target head centre (Eq. 1).
  const auto t_smooth = Clock::now();
  if (fit_face != nullptr) {
    const FaceObservation* face = fit_face;
    f.C = face->centre;
    if (options_.smooth_head_in_virtual_view && history_ > 0) {
      // C as the virtual camera would show it if it kept moving smoothly.
      const Eigen::Quaterniond R_pred =
          history_ >= 2
              ? ((R_v_prev_ * R_v_prev_prev_.conjugate()) * R_v_prev_).normalized()
              : R_v_prev_;
      const Eigen::Vector2d t_pred =
          history_ >= 2 ? Eigen::Vector2d(2.0 * t_prev_ - t_prev_prev_) : t_prev_;
      Eigen::Vector2d c;
      if (model_.Project(face->centre, R_pred, t_pred, f.R_r, &c)) f.C = c;
    }
    if (!has_H_) {
      // Start where the face appears in the virtual view now: no jump.
      Eigen::Vector2d p;
      H_prev_ = model_.Project(f.C, R_v0, t0, f.R_r, &p) ? p : f.C;
    }
    f.H = smoother_.Solve(H_prev_, f.C, output_.margin());
    f.has_target = true;
    f.flags.face_used = use_face && w.fit > 0.0;
    if (use_face) {
      // Hold it as a world-fixed camera sees it.
      held_face_ = *face;
      for (size_t i = 0; i < face->landmarks.size(); ++i) {
        const Eigen::Quaterniond R_row =
            face->landmark_rows.empty() ? f.R_r : f.rows.At(face->landmark_rows[i]);
        model_.Project(face->landmarks[i], R_reference_, Eigen::Vector2d::Zero(), R_row,
                       &held_face_.landmarks[i]);
      }
      has_held_face_ = true;
    }
  }
  f.timings.smoothing_ms = MsSince(t_smooth);

  // Solve (Eq. 5).
  const auto t_solve = Clock::now();
  Eigen::Quaterniond R_v = R_v0;
  Eigen::Vector2d t = t0;
  double q_block[4], t_block[2];
  Eigen::Map<Eigen::Vector4d> q_map(q_block);
  Eigen::Map<Eigen::Vector2d> t_map(t_block);
  q_map = R_v0.coeffs();
  t_map = t0;
  ceres::Problem::Options po;
  ceres::Problem problem(po);
  problem.AddParameterBlock(q_block, 4, new ceres::EigenQuaternionManifold);
  problem.AddParameterBlock(t_block, 2);
  std::vector<ceres::ResidualBlockId> b_fit, b_dist, b_follow, b_rot, b_trans,
      b_prot;
  const double f_r = model_.real_focal(), f_v = model_.virtual_focal();
  if (f.has_target && w.fit > 0.0) {
    const FaceObservation* face = fit_face;
    const double s = std::sqrt(w.fit / face->landmarks.size());
    for (size_t i = 0; i < face->landmarks.size(); ++i) {
      const Eigen::Quaterniond R_row =
          face->landmark_rows.empty()
              ? f.R_r
              : AlignSign(f.rows.At(face->landmark_rows[i]), f.R_r);
      b_fit.push_back(problem.AddResidualBlock(
          FittingCost::Create(face->landmarks[i], R_row, f.H, f_r, f_v, s),
          nullptr, q_block, t_block));
    }
  }
  if (w.distortion > 0.0) {
    b_dist.push_back(problem.AddResidualBlock(
        DistortionCost::Create(f.R_r, options_.terms.distortion_threshold_rad,
                               options_.terms.distortion_slope,
                               std::sqrt(w.distortion)),
        nullptr, q_block));
  }
  if (w.follow > 0.0) {
    b_follow.push_back(problem.AddResidualBlock(
        FollowingCost::Create(f.R_r, std::sqrt(w.follow)), nullptr, q_block));
  }
  if (history_ >= 1) {
    const Eigen::Quaterniond prev_delta =
        (R_v_prev_ * R_v_prev_prev_.conjugate()).normalized();
    Eigen::Quaterniond c0_target = R_v_prev_;
    if (options_.intentional_window_s > 0.0) {
      // The real camera's mean rotation per frame over the window.
      const double W = options_.intentional_window_s;
      Eigen::Quaterniond R_old;
      if (QuerySucceeded(timeline.RealRotation(
              timing.RowTime(stamp, 0.5 * (timing.height() - 1)) - FromSeconds(W),
              &R_old))) {
        const Eigen::Vector3d rate = LogSO3(f.R_r * R_old.conjugate()) / W;
        c0_target = (ExpSO3(rate * dt) * R_v_prev_).normalized();
      }
    }
    b_rot.push_back(problem.AddResidualBlock(
        RotationSmoothnessCost::Create(c0_target, R_v_prev_, prev_delta, history_ >= 2,
                                       std::sqrt(w.rotation_c0),
                                       std::sqrt(w.rotation_c1)),
        nullptr, q_block));
  }
  // On the first frame the offset's only prior is C0 towards 0.
  b_trans.push_back(problem.AddResidualBlock(
      TranslationSmoothnessCost::Create(
          history_ >= 1 ? t_prev_ : Eigen::Vector2d::Zero(), t_prev_prev_,
          history_ >= 2, std::sqrt(w.translation_c0),
          std::sqrt(w.translation_c1)),
      nullptr, t_block));
  const double shrink_px =
      options_.terms.protrusion_shrink * model_.intrinsics().width;
  if (w.protrusion > 0.0) {
    const ProtrusionReport at_init =
        protrusion_.Check(R_v0, t0, f.rows, shrink_px);
    std::vector<Eigen::Quaterniond> R_samples;
    R_samples.reserve(at_init.rows.size());
    for (double y : at_init.rows) R_samples.push_back(f.rows.At(y));
    b_prot.push_back(problem.AddResidualBlock(
        ProtrusionCost::Create(&protrusion_, std::move(R_samples), shrink_px,
                               options_.terms.protrusion_alpha, w.protrusion),
        nullptr, q_block, t_block));
  }

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
  ceres::Solve(so, &problem, &summary);
  f.solver.ran = true;
  f.solver.iterations = static_cast<int>(summary.iterations.size()) - 1;
  f.solver.termination = ceres::TerminationTypeToString(summary.termination_type);
  f.solver.initial_cost = summary.initial_cost;
  f.solver.final_cost = summary.final_cost;
  const Eigen::Quaterniond q_sol(q_map(3), q_map(0), q_map(1), q_map(2));
  const Eigen::Vector2d t_sol = t_map;
  f.solver.usable = summary.IsSolutionUsable() && q_sol.coeffs().allFinite() &&
                    t_sol.allFinite() && std::isfinite(summary.final_cost);
  f.solver.time_ms = MsSince(t_solve);
  if (f.solver.usable) {
    R_v = q_sol.normalized();
    t = t_sol;
  } else {
    f.flags.solver_failed = true;
    ++stats_.solver_failures;
  }
  f.timings.solve_ms = f.solver.time_ms;

  // Protrusion handling (§4.4): binary search towards the real pose, else
  // the previous warp.
  const auto t_prot = Clock::now();
  ProtrusionReport check = protrusion_.Check(R_v, t, f.rows, 0.0);
  if (!check.defined) {
    f.flags.protrusion_search = true;
    ++stats_.protrusion_searches;
    auto pose_at = [&](double s, Eigen::Quaterniond* q, Eigen::Vector2d* tt) {
      *q = R_v.slerp(s, f.R_r).normalized();
      *tt = (1.0 - s) * t;
    };
    Eigen::Quaterniond q_real;
    Eigen::Vector2d t_real;
    pose_at(1.0, &q_real, &t_real);
    if (protrusion_.Check(q_real, t_real, f.rows, 0.0).defined) {
      double lo = 0.0, hi = 1.0;  // lo: undefined, hi: defined
      for (int i = 0; i < options_.protrusion_search_steps; ++i) {
        const double mid = 0.5 * (lo + hi);
        Eigen::Quaterniond qm;
        Eigen::Vector2d tm;
        pose_at(mid, &qm, &tm);
        (protrusion_.Check(qm, tm, f.rows, 0.0).defined ? hi : lo) = mid;
      }
      pose_at(hi, &R_v, &t);
      f.flags.protrusion_search_s = hi;
    } else {
      // Nothing valid between P_v and P_r: apply the previous warp, i.e. the
      // same real-to-virtual rotation as on the previous frame.
      f.flags.previous_warp = true;
      ++stats_.previous_warp_fallbacks;
      if (history_ > 0) {
        R_v = AlignSign((R_v_prev_ * R_r_prev_.conjugate() * f.R_r).normalized(),
                        R_v_prev_);
        t = t_prev_;
      } else {
        R_v = f.R_r;
        t.setZero();
      }
      f.flags.undefined_pixels =
          !protrusion_.Check(R_v, t, f.rows, 0.0).defined;
    }
  }
  if (f.flags.undefined_pixels) ++stats_.undefined_frames;
  f.timings.protrusion_ms = MsSince(t_prot);

  // Energies at the final pose.
  q_map = R_v.coeffs();
  t_map = t;
  f.energies.fit = TermEnergy(&problem, b_fit);
  f.energies.distortion = TermEnergy(&problem, b_dist);
  f.energies.follow = TermEnergy(&problem, b_follow);
  f.energies.rotation = TermEnergy(&problem, b_rot);
  f.energies.translation = TermEnergy(&problem, b_trans);
  f.energies.protrusion = TermEnergy(&problem, b_prot);

  f.R_v = R_v;
  f.t = t;

  // Advance the trajectory.
  R_v_prev_prev_ = history_ > 0 ? R_v_prev_ : R_v;
  t_prev_prev_ = history_ > 0 ? t_prev_ : t;
  R_v_prev_ = history_ > 0 ? AlignSign(R_v, R_v_prev_) : R_v;
  t_prev_ = t;
  R_r_prev_ = f.R_r;
  last_stamp_ = stamp;
  history_ = std::min(history_ + 1, 2);
  if (f.has_target) {
    H_prev_ = f.H;
    has_H_ = true;
  } else {
    has_H_ = false;
  }
  ++stats_.frames;
  if (use_face) ++stats_.frames_with_face;
  f.timings.total_ms = MsSince(start);
  *frame = std::move(f);
  return Status::Ok();
}

}  // namespace steadiface
