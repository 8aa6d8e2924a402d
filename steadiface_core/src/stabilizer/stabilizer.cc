#include "steadiface_core/stabilizer/stabilizer.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/face/landmarks68.h"
#include "steadiface_core/stabilizer/face_in_camera.h"
#include "stabilizer/pose_problem.h"

namespace steadiface {
namespace {

using stabilizer_internal::Clock;
using stabilizer_internal::MsSince;

// The reach anchor's frequency (a valid one while the anchor is off).
double ReachAnchorHz(const StabilizerOptions& o) {
  return o.subject_reach_lowpass_hz > 0.0 ? o.subject_reach_lowpass_hz : 1.0;
}

// v shortened to length `r` if longer.
Eigen::Vector2d ClampNorm(const Eigen::Vector2d& v, double r) {
  const double n = v.norm();
  return n > r && n > 0.0 ? Eigen::Vector2d(v * (r / n)) : v;
}

// The face moved so that its centre is at `centre` (landmarks with it).
void MoveFaceTo(const Eigen::Vector2d& centre, FaceObservation* face) {
  ShiftFace(centre - face->centre, face);
  face->centre = centre;  // exactly, not by a difference
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
      dynamic_(options.dynamic),
      pose_centre_(options.dynamic),
      background_dynamic_(options.dynamic),
      reach_anchor_(ReachAnchorHz(options)) {}

Status Stabilizer::UpdateOptions(const StabilizerOptions& options) {
  Status s = ValidateStabilizerOptions(options);
  if (!s.ok()) return s;
  if (options.terms.protrusion_samples_per_edge !=
      options_.terms.protrusion_samples_per_edge) {
    return Status::Error(
        "terms.protrusion_samples_per_edge cannot change at run time");
  }
  if (ReachAnchorHz(options) != ReachAnchorHz(options_)) {
    reach_anchor_ = SlowMotionFilter(ReachAnchorHz(options));
    reach_anchor_fed_ = false;
  }
  options_ = options;
  smoother_ = HeadSmoother(options.head);
  dynamic_.set_options(options.dynamic);
  background_dynamic_.set_options(options.dynamic);
  pose_centre_ = PoseInvariantCentre(options.dynamic);
  if (!options.background_layer) background_ = LayerState();
  return Status::Ok();
}

void Stabilizer::SetCropRatio(double r) {
  if (r == output_.crop_ratio()) return;
  output_ = output_.WithCropRatio(r);
  protrusion_ = ProtrusionGeometry(model_, output_, options_.terms.protrusion_samples_per_edge);
}

void Stabilizer::SetTrueHeadCentre(const Eigen::Vector2d& centre) {
  has_true_head_ = centre.allFinite();
  true_head_ = centre;
}

void Stabilizer::Reset() {
  subject_ = LayerState();
  reach_limit_ = 0.0;
  background_ = LayerState();
  has_held_face_ = false;
  held_last_frame_ = false;
  handback_ = Eigen::Vector2d::Zero();
  dynamic_.Reset();
  background_dynamic_.Reset();
  pose_centre_.Reset();
  reach_anchor_fed_ = false;
  ++stats_.resets;
}

Status Stabilizer::Process(Time stamp, const OrientationTimeline& timeline,
                           const RowTiming& timing,
                           const FaceObservation* face,
                           StabilizerFrame* frame) {
  const auto start = Clock::now();
  const bool true_head = has_true_head_;  // this frame's only
  has_true_head_ = false;
  LayerState& layer = subject_;
  StabilizerFrame f;
  double dt = 0.0;
  Status s = RowRotationsStep(stamp, timeline, timing, layer, &f, &dt);
  if (!s.ok()) return s;

  const bool use_face = FaceUsable(face, options_);
  // The landmarks moved to the pose-invariant head centre: E_f, Eq. 1 and
  // the held face read it.
  FaceObservation invariant;
  FaceObservation handed;
  if (use_face) {
    invariant = pose_centre_.Apply(*face, dt);
    if (true_head) MoveFaceTo(true_head_, &invariant);
    face = HandBackStep(layer, invariant, dt, f, &handed);
  } else {
    pose_centre_.Reset();
    handback_ = Eigen::Vector2d::Zero();
  }
  // A camera fixed in the world at the epoch's first real rotation: what
  // it sees does not depend on where the gyro integration started.
  if (layer.history == 0) R_reference_ = f.R_r;
  // The usable face as that camera sees it: the variation measure's input,
  // and the face held after a loss.
  FaceObservation world_face;
  const bool world_ok = use_face && FaceInCamera(model_, *face, f.rows, f.R_r, R_reference_,
                                                 Eigen::Vector2d::Zero(), &world_face);
  const StabilizerWeights w =
      DynamicWeightsStep(stamp, timeline, use_face ? face : nullptr, world_ok ? &world_face : nullptr,
                         dt, options_.gyro_only, &dynamic_, &f);

  Eigen::Quaterniond R_v0;
  Eigen::Vector2d t0;
  InitialPoseStep(layer, f, &R_v0, &t0);

  FaceObservation held;
  const FaceObservation* fit_face = HeldFaceStep(layer, use_face ? face : nullptr, w, &held, &f);
  held_last_frame_ = f.flags.held_face;

  // The background layer does not depend on the subject's: with a reach,
  // it is solved first, and H is held within reach of where it shows the
  // face.
  const bool background_first = options_.background_layer && options_.subject_reach > 0.0;
  if (background_first) BackgroundLayer(stamp, timeline, timing, &f);
  HeadTargetStep(layer, fit_face, use_face ? &world_face : nullptr, w, R_v0, t0, dt, &f);

  PoseProblem problem;
  Eigen::Quaterniond R_v = R_v0;
  Eigen::Vector2d t = t0;
  SolveStep(stamp, timeline, timing, layer, fit_face, w, dt, &problem, &R_v, &t, &f, &stats_);

  ProtrusionStep(layer, &R_v, &t, &f, &stats_);

  EnergiesStep(R_v, t, &problem, &f);
  f.R_v = R_v;
  f.t = t;

  AdvanceStep(stamp, &layer, f);
  if (options_.background_layer && !background_first) BackgroundLayer(stamp, timeline, timing, &f);
  ++stats_.frames;
  if (use_face) ++stats_.frames_with_face;
  f.timings.total_ms = MsSince(start);
  *frame = std::move(f);
  return Status::Ok();
}

Status Stabilizer::RowRotationsStep(Time stamp, const OrientationTimeline& timeline,
                                    const RowTiming& timing, const LayerState& layer,
                                    StabilizerFrame* f, double* dt) {
  if (layer.history > 0 && stamp <= layer.last_stamp) {
    std::ostringstream err;
    err << "frame stamp " << ToSeconds(stamp)
        << " s is not after the previous one (" << ToSeconds(layer.last_stamp)
        << " s); reset() the stabilizer after a time jump";
    return Status::Error(err.str());
  }
  if (timing.height() != model_.intrinsics().height) {
    return Status::Error("row timing is for another image height");
  }
  f->stamp = stamp;
  const QueryResult q = RowRotations::Build(
      timeline, timing, stamp, options_.row_rotation_samples, &f->rows);
  if (!QuerySucceeded(q)) {
    ++stats_.no_gyro_frames;
    return Status::Error(
        "gyro does not cover the frame's rows (first row " +
        std::to_string(ToSeconds(timing.FirstRowTime(stamp))) + " s, last row " +
        std::to_string(ToSeconds(timing.LastRowTime(stamp))) + " s)");
  }
  StartLayerFrame(layer, stamp, f, dt);
  return Status::Ok();
}

void Stabilizer::StartLayerFrame(const LayerState& layer, Time stamp, StabilizerFrame* f,
                                 double* dt) const {
  f->R_r = f->rows.Middle();
  if (layer.history > 0) f->R_r = AlignSign(f->R_r, layer.R_r_prev);
  *dt = layer.history > 0 ? ToSeconds(stamp - layer.last_stamp) : 0.0;
  f->flags.first_frame = layer.history == 0;
}

StabilizerWeights Stabilizer::DynamicWeightsStep(Time stamp, const OrientationTimeline& timeline,
                                                 const FaceObservation* face,
                                                 const FaceObservation* world_face, double dt,
                                                 bool without_fit, DynamicWeights* dynamic,
                                                 StabilizerFrame* f) {
  // Dynamic weights (§4.4). `face` is null unless usable.
  const auto t_weights = Clock::now();
  double mean_speed = -1.0;
  if (!timeline.MeanAngularSpeed(
          stamp - FromSeconds(options_.dynamic.gyro_window_s), stamp,
          &mean_speed)) {
    mean_speed = -1.0;
  }
  const FaceObservation* stabilized = world_face != nullptr ? world_face : face;
  f->factors = dynamic->Update(dt, mean_speed, face,
                               stabilized ? stabilized->centre : Eigen::Vector2d::Zero(),
                               stabilized ? stabilized->scale : 0.0);
  StabilizerWeights w = options_.weights;
  w.fit = without_fit ? 0.0 : w.fit * f->factors.fit;
  w.rotation_c0 *= f->factors.smoothness;
  w.rotation_c1 *= f->factors.smoothness;
  w.translation_c0 *= f->factors.smoothness;
  w.translation_c1 *= f->factors.smoothness;
  f->weights = w;
  f->timings.weights_ms = MsSince(t_weights);
  return w;
}

void Stabilizer::InitialPoseStep(const LayerState& layer, const StabilizerFrame& f,
                                 Eigen::Quaterniond* R_v0, Eigen::Vector2d* t0) const {
  // Initial pose (paper Eq. 12): identity-equivalent (virtual = real) on the
  // first frame, then the real rotation change applied to the previous
  // virtual rotation, and the previous offset.
  *R_v0 = f.R_r;
  *t0 = Eigen::Vector2d::Zero();
  if (layer.history > 0) {
    *R_v0 = AlignSign(((f.R_r * layer.R_r_prev.conjugate()) * layer.R_v_prev).normalized(),
                      layer.R_v_prev);
    *t0 = layer.t_prev;
  }
}

const FaceObservation* Stabilizer::HeldFaceStep(const LayerState& layer,
                                                const FaceObservation* face,
                                                const StabilizerWeights& w,
                                                FaceObservation* held, StabilizerFrame* f) {
  // The face the fitting term uses: this frame's (`face`, null unless
  // usable), or while w_f fades out after a loss, the last one held fixed
  // in the world.
  const FaceObservation* fit_face = face;
  if (face == nullptr && has_held_face_ && layer.has_H && w.fit > 1e-3 * options_.weights.fit &&
      HeldFaceNow(*f, held)) {
    fit_face = held;
    f->flags.held_face = true;
  }
  if (fit_face == nullptr) has_held_face_ = false;
  return fit_face;
}

bool Stabilizer::HeldFaceNow(const StabilizerFrame& f, FaceObservation* held) const {
  *held = held_face_;
  for (size_t i = 0; i < held->landmarks.size(); ++i) {
    const Eigen::Quaterniond R_row =
        held->landmark_rows.empty() ? f.R_r : f.rows.At(held->landmark_rows[i]);
    if (!model_.Unproject(held_face_.landmarks[i], R_reference_, Eigen::Vector2d::Zero(), R_row,
                          &held->landmarks[i])) {
      return false;
    }
  }
  ComputeCentreAndScale(held);
  return held->centre.allFinite();
}

const FaceObservation* Stabilizer::HandBackStep(const LayerState& layer,
                                                const FaceObservation& face, double dt,
                                                const StabilizerFrame& f, FaceObservation* out) {
  // A face back after it was held (lost) sits where the output did not
  // follow it meanwhile: the head's own motion during the loss. Shifted
  // back onto the held face, it rejoins its landmarks over handback_time_s
  // instead of pulling the camera in one frame. (Fitted landmarks after a
  // followed head are taken as they come: handed back so, turn_away's head
  // was up to 21 % less steady; docs/evaluation.md.)
  FaceObservation last;
  if (held_last_frame_ && has_held_face_ && layer.has_H &&
      options_.dynamic.handback_time_s > 0.0 && HeldFaceNow(f, &last)) {
    handback_ = face.centre - last.centre;
  } else if (dt > 0.0 && options_.dynamic.handback_time_s > 0.0) {
    handback_ *= std::exp(-dt / options_.dynamic.handback_time_s);
  } else {
    handback_.setZero();
  }
  if (!handback_.allFinite()) handback_.setZero();
  *out = face;
  ShiftFace(-handback_, out);
  return out;
}

void Stabilizer::HeadTargetStep(const LayerState& layer, const FaceObservation* fit_face,
                                const FaceObservation* world_face, const StabilizerWeights& w,
                                const Eigen::Quaterniond& R_v0, const Eigen::Vector2d& t0,
                                double dt, StabilizerFrame* f) {
  // Target head centre (Eq. 1).
  const auto t_smooth = Clock::now();
  if (fit_face != nullptr) {
    const FaceObservation* face = fit_face;
    f->C = face->centre;
    if (options_.smooth_head_in_virtual_view && layer.history > 0) {
      // C as the virtual camera would show it if it kept moving smoothly.
      const Eigen::Quaterniond R_pred =
          layer.history >= 2
              ? ((layer.R_v_prev * layer.R_v_prev_prev.conjugate()) * layer.R_v_prev).normalized()
              : layer.R_v_prev;
      const Eigen::Vector2d t_pred = layer.history >= 2
                                         ? Eigen::Vector2d(2.0 * layer.t_prev - layer.t_prev_prev)
                                         : layer.t_prev;
      FaceObservation seen;
      if (FaceInCamera(model_, *face, f->rows, f->R_r, R_pred, t_pred, &seen)) f->C = seen.centre;
    }
    Eigen::Vector2d H_prev = layer.H_prev;
    if (!layer.has_H) {
      // Start where the face appears in the virtual view now: no jump. With
      // a history that is the view the virtual camera would show if it kept
      // moving smoothly (f->C): R_v0 carries this frame's shake, so on a
      // shaking camera a face found mid-sequence would start its target off
      // by the shake of that one frame and hold the output there (robot
      // preset: an 8 px step at the acquisition, now 1 px).
      FaceObservation seen;
      if (options_.smooth_head_in_virtual_view && layer.history > 0) {
        H_prev = f->C;
      } else {
        H_prev = FaceInCamera(model_, *face, f->rows, f->R_r, R_v0, t0, &seen) ? seen.centre
                                                                                 : f->C;
      }
    }
    // Eq. 1's constraint |H - C| < r is a reachability bound when C is in
    // the real frame (the paper): a crop that moves by at most r can show
    // the head anywhere within r of where the real camera sees it. With C in
    // the predicted virtual view, the box around C is not that set, and
    // clamping H to it drags the target along with every move the margin
    // forces on the virtual camera, so the head follows the shake it should
    // have been held against (shake preset: 53.8 -> 49.4 px head jitter
    // without it; the presets whose margin suffices are unchanged). There,
    // reachability is left to E_p and the protrusion search, which check it
    // exactly, rolling shutter included.
    const double unbounded = std::numeric_limits<double>::infinity();
    f->H = smoother_.Solve(H_prev, f->C,
                           options_.smooth_head_in_virtual_view
                               ? Eigen::Vector2d(unbounded, unbounded)
                               : output_.margin());
    if (f->background.valid) HoldWithinBackgroundReach(*face, dt, f);
    f->has_target = true;
    f->flags.face_used = world_face != nullptr && w.fit > 0.0;
    if (world_face != nullptr) {
      // Hold it as a world-fixed camera sees it.
      held_face_ = *world_face;
      has_held_face_ = true;
    }
  }
  f->timings.smoothing_ms = MsSince(t_smooth);
}

void Stabilizer::HoldWithinBackgroundReach(const FaceObservation& face, double dt,
                                           StabilizerFrame* f) {
  // Where the background layer shows the face, and the jaw's width there:
  // the distance between the jaw's end points (landmarks 0 and 16). The
  // layered region measures its jaw width as the jaw's horizontal extent
  // (SubjectRegionTracker); the two agree on a frontal, upright face and
  // differ under roll, so a reach equal to band width x cap is only about
  // what the band absorbs.
  FaceObservation seen;
  const bool fed = reach_anchor_fed_ && reach_anchor_frame_ + 1 == stats_.frames;
  reach_anchor_fed_ = false;
  if (!FaceInCamera(model_, face, f->rows, f->R_r, f->background.R_v, f->background.t, &seen)) {
    return;
  }
  const double jaw = seen.landmarks.size() == landmarks68::kCount
                         ? (seen.landmarks[landmarks68::kJawRightEnd] -
                            seen.landmarks[landmarks68::kJawLeftEnd]).norm()
                                                 : 2.0 * seen.scale;
  const double fraction = reach_limit_ > 0.0 ? std::min(options_.subject_reach, reach_limit_)
                                              : options_.subject_reach;
  const double reach = fraction * jaw;
  f->subject_reach = reach;
  Eigen::Vector2d H = f->H;
  if (options_.subject_reach_lowpass_hz > 0.0) {
    // Follow the slow part S of where the background layer shows the face
    // (its drift): Eq. 1's H may hold still only within the hold of S, so
    // the rest of the reach is left for the face's fast motion, which H
    // does not follow. A face that appears or comes back restarts S at its
    // position (no jump: H starts there too).
    if (!fed) reach_anchor_.Reset();
    const Eigen::Vector2d S = reach_anchor_.Update(seen.centre, fed ? dt : 0.0);
    reach_anchor_fed_ = true;
    reach_anchor_frame_ = stats_.frames;
    H = S + ClampNorm(H - S, options_.subject_reach_hold * reach);
  }
  // A disc, not Eq. 1's box: the band absorbs an offset in any direction
  // alike.
  f->H = seen.centre + ClampNorm(H - seen.centre, reach);
}

void Stabilizer::ProtrusionStep(const LayerState& layer, Eigen::Quaterniond* R_v,
                                Eigen::Vector2d* t, StabilizerFrame* f, StabilizerStats* stats) {
  // Protrusion handling (§4.4): binary search towards the real pose, else
  // the previous warp.
  const auto t_prot = Clock::now();
  f->R_v_solved = *R_v;
  f->t_solved = *t;
  const ProtrusionReport check = protrusion_.Check(*R_v, *t, f->rows, 0.0);
  if (!check.defined) {
    f->flags.protrusion_search = true;
    ++stats->protrusion_searches;
    const Eigen::Quaterniond R_sol = *R_v;
    const Eigen::Vector2d t_sol = *t;
    auto pose_at = [&](double s, Eigen::Quaterniond* q, Eigen::Vector2d* tt) {
      *q = R_sol.slerp(s, f->R_r).normalized();
      *tt = (1.0 - s) * t_sol;
    };
    Eigen::Quaterniond q_real;
    Eigen::Vector2d t_real;
    pose_at(1.0, &q_real, &t_real);
    if (protrusion_.Check(q_real, t_real, f->rows, 0.0).defined) {
      double lo = 0.0, hi = 1.0;  // lo: undefined, hi: defined
      for (int i = 0; i < options_.protrusion_search_steps; ++i) {
        const double mid = 0.5 * (lo + hi);
        Eigen::Quaterniond qm;
        Eigen::Vector2d tm;
        pose_at(mid, &qm, &tm);
        (protrusion_.Check(qm, tm, f->rows, 0.0).defined ? hi : lo) = mid;
      }
      pose_at(hi, R_v, t);
      f->flags.protrusion_search_s = hi;
    } else {
      // Nothing valid between P_v and P_r: apply the previous warp, i.e. the
      // same real-to-virtual rotation as on the previous frame.
      f->flags.previous_warp = true;
      ++stats->previous_warp_fallbacks;
      if (layer.history > 0) {
        *R_v = AlignSign((layer.R_v_prev * layer.R_r_prev.conjugate() * f->R_r).normalized(),
                         layer.R_v_prev);
        *t = layer.t_prev;
      } else {
        *R_v = f->R_r;
        t->setZero();
      }
      f->flags.undefined_pixels = !protrusion_.Check(*R_v, *t, f->rows, 0.0).defined;
    }
  }
  if (f->flags.undefined_pixels) ++stats->undefined_frames;
  f->timings.protrusion_ms = MsSince(t_prot);
}

void Stabilizer::BackgroundLayer(Time stamp, const OrientationTimeline& timeline,
                                 const RowTiming& timing, StabilizerFrame* f) {
  // The same steps as the subject layer without a face (w_f = 0, no held
  // face, no head target): exactly what a gyro-only run computes, with this
  // layer's own trajectory, dynamic weights and counters.
  LayerState& layer = background_;
  StabilizerFrame b;
  b.stamp = stamp;
  b.rows = f->rows;
  double dt = 0.0;
  StartLayerFrame(layer, stamp, &b, &dt);
  const StabilizerWeights w =
      DynamicWeightsStep(stamp, timeline, nullptr, nullptr, dt, /*without_fit=*/true,
                         &background_dynamic_, &b);
  Eigen::Quaterniond R_v;
  Eigen::Vector2d t;
  InitialPoseStep(layer, b, &R_v, &t);
  PoseProblem problem;
  SolveStep(stamp, timeline, timing, layer, nullptr, w, dt, &problem, &R_v, &t, &b,
            &background_stats_);
  ProtrusionStep(layer, &R_v, &t, &b, &background_stats_);
  b.R_v = R_v;
  b.t = t;
  AdvanceStep(stamp, &layer, b);
  f->background.valid = true;
  f->background.R_v = R_v;
  f->background.t = t;
  f->background.R_v_solved = b.R_v_solved;
  f->background.t_solved = b.t_solved;
  f->background.flags = b.flags;
  f->background.solver = b.solver;
}

void Stabilizer::AdvanceStep(Time stamp, LayerState* layer, const StabilizerFrame& f) const {
  // Advance the trajectory.
  const Eigen::Quaterniond& R_v = f.R_v;
  const Eigen::Vector2d& t = f.t;
  layer->R_v_prev_prev = layer->history > 0 ? layer->R_v_prev : R_v;
  layer->t_prev_prev = layer->history > 0 ? layer->t_prev : t;
  layer->R_v_prev = layer->history > 0 ? AlignSign(R_v, layer->R_v_prev) : R_v;
  layer->t_prev = t;
  layer->R_r_prev = f.R_r;
  layer->last_stamp = stamp;
  layer->history = std::min(layer->history + 1, 2);
  if (f.has_target) {
    layer->H_prev = f.H;
    layer->has_H = true;
  } else {
    layer->has_H = false;
  }
}

}  // namespace steadiface
