#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/common/tracking_lowpass.h"
#include "steadiface_core/face/face_observation.h"
#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/gyro/row_rotations.h"
#include "steadiface_core/stabilizer/dynamic_weights.h"
#include "steadiface_core/stabilizer/head_smoother.h"
#include "steadiface_core/stabilizer/pose_invariant_centre.h"
#include "steadiface_core/stabilizer/stabilizer_options.h"
#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/warp/protrusion.h"

namespace steadiface {

/// Energy of each term at the returned pose, weights included
/// (w_term * E_term), and their sum.
struct TermEnergies {
  double fit = 0.0;
  double distortion = 0.0;
  double follow = 0.0;
  double rotation = 0.0;
  double translation = 0.0;
  double protrusion = 0.0;
  double horizon = 0.0;  ///< E_h (ours: the level horizon), 0 when off
  double total() const {
    return fit + distortion + follow + rotation + translation + protrusion + horizon;
  }
};

/// What Ceres reported for this frame's solve.
struct SolverReport {
  bool ran = false;
  bool usable = false;
  int iterations = 0;
  std::string termination;  ///< CONVERGENCE, NO_CONVERGENCE, FAILURE, ...
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double time_ms = 0.0;
  /// The wall-time cap ran out before the first step (a stall) and the
  /// solve was run again under the iteration cap alone.
  bool restarted = false;
  /// E_p's tolerance α this solve used (fraction of the width): the face's
  /// (terms.protrusion_alpha_face) only in proportion to a w_f that E_f
  /// actually fitted, the paper's stiff wall otherwise. 0 when E_p was off.
  double protrusion_alpha = 0.0;
};

/// Why the pose is what it is.
struct StabilizerFlags {
  bool face_used = false;          ///< a face entered E_f this frame
  /// The face was lost: E_f fits the last landmarks, held fixed in the world
  /// (moved by the gyro), while w_f fades out, so the pose does not jump.
  bool held_face = false;
  bool solver_failed = false;      ///< solve unusable; kept previous warp
  bool protrusion_search = false;  ///< binary search toward P_r ran
  double protrusion_search_s = 0.0;  ///< fraction moved towards P_r [0-1]
  bool previous_warp = false;      ///< nothing valid; previous warp reused
  bool undefined_pixels = false;   ///< output still has undefined pixels
  bool first_frame = false;
};

struct StabilizerTimings {
  double weights_ms = 0.0;
  double smoothing_ms = 0.0;
  double solve_ms = 0.0;
  double protrusion_ms = 0.0;
  double total_ms = 0.0;
};

/// Everything about one stabilized frame.
struct StabilizerFrame {
  Time stamp;
  /// Virtual rotation R_v (world -> virtual camera) and principal offset t.
  Eigen::Quaterniond R_v = Eigen::Quaterniond::Identity();
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
  /// The solve's pose before the protrusion search moved it towards the
  /// real one (R_v, t when the search did not run): the margin the motion
  /// asked for, which the dynamic crop follows.
  Eigen::Quaterniond R_v_solved = Eigen::Quaterniond::Identity();
  Eigen::Vector2d t_solved = Eigen::Vector2d::Zero();
  /// Real rotation at the middle row, and per row.
  Eigen::Quaterniond R_r = Eigen::Quaterniond::Identity();
  RowRotations rows;
  /// Target head centre H and landmark centre C (valid when has_target).
  bool has_target = false;
  Eigen::Vector2d H = Eigen::Vector2d::Zero();
  Eigen::Vector2d C = Eigen::Vector2d::Zero();
  /// Layered mode: the radius of the disc, around where the background
  /// layer shows the face, that H was held within (subject_reach, or the
  /// warp's SetReachLimit if less, times the jaw width) [normalized]; 0 when
  /// H was not held (no background layer, no target).
  double subject_reach = 0.0;
  /// Weights in effect (base weights times the dynamic factors).
  StabilizerWeights weights;
  WeightFactors factors;
  TermEnergies energies;
  SolverReport solver;
  StabilizerFlags flags;
  StabilizerTimings timings;
  /// The background layer's pose (StabilizerOptions::background_layer):
  /// the same optimization without E_f, with its own smoothness state.
  struct LayerPose {
    bool valid = false;  ///< solved this frame (background_layer on)
    Eigen::Quaterniond R_v = Eigen::Quaterniond::Identity();
    Eigen::Vector2d t = Eigen::Vector2d::Zero();
    /// Before the protrusion search (as StabilizerFrame::R_v_solved).
    Eigen::Quaterniond R_v_solved = Eigen::Quaterniond::Identity();
    Eigen::Vector2d t_solved = Eigen::Vector2d::Zero();
    StabilizerFlags flags;
    SolverReport solver;
  };
  LayerPose background;
};

/// The level horizon for the frames to come (the pipeline's output/horizon):
/// gravity's "up" in the gyro's world frame, the weight w_h of E_h, and
/// whether E_d and E_o measure the virtual camera against the real one
/// turned level about its optical axis (lock: the roll is not followed).
struct HorizonTarget {
  bool active = false;
  Eigen::Vector3d up_world = Eigen::Vector3d(0.0, -1.0, 0.0);
  double weight = 0.0;
  /// E_h leaves a roll within this alone (level's tolerance; 0 for lock)
  /// [rad].
  double tolerance_rad = 0.0;
  bool level_reference = false;
};

/// Running counters since start (reset() keeps them).
struct StabilizerStats {
  uint64_t frames = 0;
  uint64_t frames_with_face = 0;
  uint64_t solver_failures = 0;
  /// Solves whose time cap ran out before their first step and were rerun.
  uint64_t solver_restarts = 0;
  uint64_t protrusion_searches = 0;
  uint64_t previous_warp_fallbacks = 0;
  uint64_t undefined_frames = 0;
  uint64_t no_gyro_frames = 0;
  uint64_t resets = 0;
};

/// The face-centric stabilizer (paper §3.2 and §4): per frame and causally,
/// smooth the head target (Eq. 1), adjust weights (§4.4), solve for the
/// virtual pose {R_v, t} minimizing
///   w_f E_f + w_d E_d + w_o E_o + w_r E_r + w_t E_t + w_p E_p    (Eq. 5)
/// with Ceres, then remove any protrusion by binary search between the
/// solution and the real pose, falling back to the previous warp when
/// nothing valid exists.
///
/// Deterministic (single-threaded Ceres, no wall-clock dependence unless
/// solver.max_time_s runs out after the solve's first step; a cap that
/// runs out before it, a stall, reruns the solve under the iteration cap).
/// Not thread-safe: one instance per stream.
class Stabilizer {
 public:
  static Status Create(const CameraModel& model, const OutputOptions& output,
                       const StabilizerOptions& options,
                       std::unique_ptr<Stabilizer>* out);

  /// Processes the frame stamped `stamp` (camera clock). `face` may be null
  /// or invalid (then gyro-only with w_f fading out). Fails, leaving the
  /// state untouched, when the timeline does not cover the frame's rows.
  Status Process(Time stamp, const OrientationTimeline& timeline,
                 const RowTiming& timing, const FaceObservation* face,
                 StabilizerFrame* frame);

  /// Replaces the tunable options (weights, terms, dynamic, solver, head,
  /// gyro_only) from the next frame on. Validated; on error nothing changes.
  Status UpdateOptions(const StabilizerOptions& options);

  /// Layered mode: the largest offset between the layers at the face that
  /// the warp's band absorbs now, in jaw widths (the pipeline passes the
  /// last frame's LayerBlendReport::reach_px over the jaw width). H is held
  /// within min(subject_reach, this) of where the background layer shows the
  /// face. <= 0: subject_reach alone.
  void SetReachLimit(double jaw_widths) { reach_limit_ = jaw_widths; }

  /// The level horizon from the next Process() on (both layers); an
  /// inactive target (the default) leaves the roll to the paper's terms.
  void SetHorizon(const HorizonTarget& horizon) { horizon_ = horizon; }

  /// The dynamic crop: the window E_p, the protrusion search and Eq. 1's
  /// margin keep inside the real frame, from the next Process() on, is
  /// (1 - 2 r) of the frame (OutputGeometry::WithCropRatio).
  void SetCropRatio(double r);

  /// Evaluation only (steadiface_evaluate --true-head): the next Process()
  /// takes `centre` [normalized] as its face's pose-invariant head centre,
  /// the landmarks moved with it, in place of the tracker's. A frame
  /// without a face stays without one. What a perfect tracker would give.
  void SetTrueHeadCentre(const Eigen::Vector2d& centre);

  /// Forgets the trajectory (time jumped, new epoch). Counters are kept.
  void Reset();

  const StabilizerOptions& options() const { return options_; }
  const StabilizerStats& stats() const { return stats_; }
  const OutputGeometry& output_geometry() const { return output_; }
  const ProtrusionGeometry& protrusion() const { return protrusion_; }

 private:
  Stabilizer(const CameraModel& model, const OutputGeometry& output,
             const StabilizerOptions& options);

  // The trajectory of one virtual camera (a layer): what the smoothness
  // terms, the initial pose and the head target remember between frames.
  struct LayerState {
    int history = 0;  // frames since start/reset (capped at 2)
    Time last_stamp;
    Eigen::Quaterniond R_v_prev = Eigen::Quaterniond::Identity();
    Eigen::Quaterniond R_v_prev_prev = Eigen::Quaterniond::Identity();
    Eigen::Quaterniond R_r_prev = Eigen::Quaterniond::Identity();
    Eigen::Vector2d t_prev = Eigen::Vector2d::Zero();
    Eigen::Vector2d t_prev_prev = Eigen::Vector2d::Zero();
    bool has_H = false;
    Eigen::Vector2d H_prev = Eigen::Vector2d::Zero();
  };
  struct PoseProblem;  // one frame's Ceres problem (src/stabilizer/pose_problem.h)

  // Process(), step by step, in this order.
  // Row rotations: validates the stamp, builds the per-row real rotations
  // and R_r (middle row), and the time since the layer's previous frame.
  Status RowRotationsStep(Time stamp, const OrientationTimeline& timeline,
                          const RowTiming& timing, const LayerState& layer,
                          StabilizerFrame* f, double* dt);
  // A layer's view of a frame whose rows are built: R_r (middle row, sign
  // aligned with the layer's previous one), the time since the layer's
  // previous frame, the first-frame flag.
  void StartLayerFrame(const LayerState& layer, Time stamp, StabilizerFrame* f,
                       double* dt) const;
  // Dynamic weights (§4.4); `face` is null unless usable, `world_face` (the
  // face as the reference camera sees it) null unless it could be moved there.
  // `without_fit`: w_f = 0 (gyro-only, or the background layer).
  StabilizerWeights DynamicWeightsStep(Time stamp, const OrientationTimeline& timeline,
                                       const FaceObservation* face,
                                       const FaceObservation* world_face, double dt,
                                       bool without_fit, DynamicWeights* dynamic,
                                       StabilizerFrame* f);
  // Initial pose (Eq. 12).
  void InitialPoseStep(const LayerState& layer, const StabilizerFrame& f,
                       Eigen::Quaterniond* R_v0, Eigen::Vector2d* t0) const;
  // The face shifted by the hand-back offset: a face back after it was
  // held jumps by what the output did not follow meanwhile; the jump is
  // taken up over options_.dynamic.handback_time_s (written to *out).
  const FaceObservation* HandBackStep(const LayerState& layer, const FaceObservation& face,
                                      double dt, const StabilizerFrame& f, FaceObservation* out);
  // The held face where the world-fixed reference camera puts it in this
  // frame (f: R_r and the rows); false when it cannot be projected.
  bool HeldFaceNow(const StabilizerFrame& f, FaceObservation* held) const;
  // The face E_f fits: this frame's, or the held one while w_f fades out
  // (then written to *held); null when none.
  const FaceObservation* HeldFaceStep(const LayerState& layer, const FaceObservation* face,
                                      const StabilizerWeights& w, FaceObservation* held,
                                      StabilizerFrame* f);
  // Head target H (Eq. 1), and the held face updated from a usable one:
  // `world_face`, this frame's usable face as the reference camera sees it
  // (null when there is none).
  // H within options_.subject_reach of where the background layer (solved
  // before, in f->background) shows the face, and within the hold of that
  // position's slow part (reach_anchor_); `dt` [s] since the last frame.
  void HoldWithinBackgroundReach(const FaceObservation& face, double dt, StabilizerFrame* f);
  void HeadTargetStep(const LayerState& layer, const FaceObservation* fit_face,
                      const FaceObservation* world_face, const StabilizerWeights& w,
                      const Eigen::Quaterniond& R_v0, const Eigen::Vector2d& t0, double dt,
                      StabilizerFrame* f);
  // Solve (Eq. 5) from the initial pose in *R_v, *t; the solution replaces
  // it when usable.
  void SolveStep(Time stamp, const OrientationTimeline& timeline, const RowTiming& timing,
                 const LayerState& layer, const FaceObservation* fit_face,
                 const StabilizerWeights& w, double dt, PoseProblem* problem,
                 Eigen::Quaterniond* R_v, Eigen::Vector2d* t, StabilizerFrame* f,
                 StabilizerStats* stats);
  // SolveStep's pieces: the residual blocks of E_f (Eq. 6); of E_d, E_o
  // and E_r (Eqs. 7-9); of E_t and E_p (Eqs. 10-11); then the solve (the
  // solution replaces *R_v, *t when usable).
  void AddFitTerms(const FaceObservation* fit_face, const StabilizerWeights& w,
                   const StabilizerFrame& f, PoseProblem* problem) const;
  void AddRotationTerms(Time stamp, const OrientationTimeline& timeline, const RowTiming& timing,
                        const LayerState& layer, const StabilizerWeights& w, double dt,
                        const StabilizerFrame& f, PoseProblem* problem) const;
  void AddOffsetTerms(const LayerState& layer, const StabilizerWeights& w,
                      const Eigen::Quaterniond& R_v0, const Eigen::Vector2d& t0,
                      const StabilizerFrame& f, PoseProblem* problem);
  void RunSolve(const Eigen::Quaterniond& R_v0, const Eigen::Vector2d& t0, PoseProblem* problem,
                Eigen::Quaterniond* R_v, Eigen::Vector2d* t, StabilizerFrame* f,
                StabilizerStats* stats) const;
  // Protrusion search towards the real pose, else the previous warp.
  void ProtrusionStep(const LayerState& layer, Eigen::Quaterniond* R_v, Eigen::Vector2d* t,
                      StabilizerFrame* f, StabilizerStats* stats);
  // The background layer for this frame (rows from the subject's frame).
  void BackgroundLayer(Time stamp, const OrientationTimeline& timeline, const RowTiming& timing,
                       StabilizerFrame* f);
  // The rotation E_d and E_o measure the virtual camera against: the real
  // one, or with a locked horizon the real one turned level.
  Eigen::Quaterniond HorizonReference(const Eigen::Quaterniond& R_r) const;
  // Every term's energy at the final pose.
  void EnergiesStep(const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                    PoseProblem* problem, StabilizerFrame* f) const;
  // Advances the layer's trajectory to this frame (f.R_v, f.t set).
  void AdvanceStep(Time stamp, LayerState* layer, const StabilizerFrame& f) const;

  const CameraModel model_;
  // The crop in effect (SetCropRatio) and its protrusion boundary.
  OutputGeometry output_;
  ProtrusionGeometry protrusion_;
  HorizonTarget horizon_;
  StabilizerOptions options_;
  HeadSmoother smoother_;
  DynamicWeights dynamic_;
  PoseInvariantCentre pose_centre_;
  StabilizerStats stats_;

  // The face-following layer's trajectory (the paper's one virtual camera).
  LayerState subject_;
  // The background layer (options_.background_layer): its trajectory, its
  // dynamic weights (as a gyro-only run's) and its own counters.
  LayerState background_;
  DynamicWeights background_dynamic_;
  StabilizerStats background_stats_;
  // Real rotation of the epoch's first frame: the world-fixed reference
  // camera for the variation measure and the held face (so results do not
  // depend on where gyro integration started).
  Eigen::Quaterniond R_reference_ = Eigen::Quaterniond::Identity();
  // Last usable face, as seen by the reference camera (R_reference_), for
  // the fade-out after a loss.
  bool has_held_face_ = false;
  FaceObservation held_face_;
  // The last frame fitted the held face, and the hand-back offset
  // (HandBackStep) [normalized].
  bool held_last_frame_ = false;
  Eigen::Vector2d handback_ = Eigen::Vector2d::Zero();
  // The slow part of where the background layer shows the face
  // (subject_reach_lowpass_hz), and the frame (stats_.frames) it was last
  // fed: it restarts after a frame without it.
  SlowMotionFilter reach_anchor_;
  // SetReachLimit's bound on subject_reach [jaw widths]; <= 0: none.
  double reach_limit_ = 0.0;
  // SetTrueHeadCentre's centre for the next Process() [normalized].
  bool has_true_head_ = false;
  Eigen::Vector2d true_head_ = Eigen::Vector2d::Zero();
  uint64_t reach_anchor_frame_ = 0;
  bool reach_anchor_fed_ = false;
};

}  // namespace steadiface
