#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/gyro/row_rotations.h"
#include "steadiface_core/sim/simulator.h"
#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/warp/protrusion.h"

namespace steadiface {
namespace eval {

/// The warp a stabilizer applied to one frame, in one of three forms.
struct FrameWarp {
  enum class Kind {
    kIdentity,    ///< no stabilization: output = input
    kPose,        ///< steadiface: virtual pose + per-row real rotation
    kHomography,  ///< any per-frame homography (input px -> output px)
    kMesh,        ///< a warp mesh (output vertices -> input px), e.g. layered
    /// The composite: the subject through (R_v, t), the far scene through the
    /// background layer's (R_b, t_b), hidden where the subject, placed by
    /// (R_v, t), covers it in the output. Scored as if matte and plate were
    /// exact; their errors against the truth are the composite's own
    /// figures (CompositeQuality).
    kComposite,
  };
  Kind kind = Kind::kIdentity;
  Eigen::Quaterniond R_v = Eigen::Quaterniond::Identity();
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
  RowRotations rows;
  /// kComposite: the background layer's pose (kMesh from the layered
  /// warp: the same, for the horizon's roll).
  Eigen::Quaterniond R_b = Eigen::Quaterniond::Identity();
  Eigen::Vector2d t_b = Eigen::Vector2d::Zero();
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  /// kMesh: vertex columns / rows at output px u, v; the source (input px)
  /// of vertex (i, j) at [j * u.size() + i]; optionally the background
  /// layer's mesh and each vertex's layer blend (for the band's figures).
  std::vector<double> mesh_u, mesh_v;
  std::vector<Eigen::Vector2f> mesh_source, mesh_background;
  std::vector<double> mesh_blend;
  /// The stabilizer's head target H (Eq. 1) in the virtual view, when it
  /// had one (for the target's per-frame steps); optional.
  bool has_head_target = false;
  Eigen::Vector2d head_target = Eigen::Vector2d::Zero();
  /// Per-stage time of this frame [ms] (name, value); optional.
  std::vector<std::pair<std::string, double>> stage_ms;
  /// The crop ratio this frame was made with (the dynamic crop: kPose and
  /// kComposite map through the output geometry at it); NaN: the
  /// scorecard's output geometry's.
  double crop_ratio = NAN;
  /// The margin the frame's solved pose asked for (CropNeed); optional.
  double crop_need = NAN;
};

/// The numbers of one method on one sequence.
struct Score {
  int frames = 0;
  /// RMS of the > highpass_hz part of the output head-centre trajectory
  /// [output px] and as a fraction of the output diagonal.
  double head_jitter_px = 0.0, head_jitter_frac = 0.0;
  /// The same for far-background points (mean over the points).
  double background_jitter_px = 0.0, background_jitter_frac = 0.0;
  /// Jitter of the head relative to the background: the high-pass RMS of
  /// head_out - background_out, per background point over its longest run
  /// of frames with both in view, mean over the points [output px]. One
  /// rotation and offset per frame moves the head and the far background
  /// alike, so no such warp can change this much: it is about the input's
  /// value times the output zoom (the head's own motion and the camera's
  /// translation, i.e. parallax). NaN without such a run.
  double relative_jitter_px = NAN;
  /// The least background jitter any output with this head jitter can have,
  /// by the triangle inequality J(b) >= J(h - b) - J(h) per point on the same
  /// frames (mean over the points) [output px]. Holding the head still
  /// costs at least this much background steadiness. NaN as above.
  double background_floor_px = NAN;
  /// Liu et al. 2013 stability: energy in the 2nd-6th lowest frequency bins
  /// of the frame-to-frame motion over its total energy, excluding DC
  /// (1 = perfectly smooth), for the head and the background.
  double head_stability = 0.0, background_stability = 0.0;
  /// Output area over input area (1 = no crop), mean over frames.
  double cropping = 1.0;
  /// The width the output keeps of the input's, 1 - 2 r [-]: mean and
  /// least over frames; the largest per-frame change and the RMS of its
  /// second difference (the zoom's breathing) [-].
  double kept_width_mean = 1.0, kept_width_min = 1.0;
  double kept_width_max_step = 0.0, kept_width_rms_accel = 0.0;
  /// Min over frames of the ratio of the smaller to the larger singular
  /// value of the warp's local linear part at the output centre (1 = no
  /// distortion).
  double distortion = 1.0;
  /// Fraction of frames with any undefined output pixel.
  double undefined_fraction = 0.0;
  /// The horizon: RMS over frames of the output's roll against the true
  /// gravity (the scene's layer: R_v for kPose, R_b for kComposite and
  /// kMesh), and of the input's [deg]. NaN for other warps.
  double output_roll_rms_deg = NAN, input_roll_rms_deg = NAN;
  /// Jitter of the far background where it is visible: a denser grid of
  /// directions, each point dropped on frames where the subject (face or
  /// torso) covers it, mean over the points [output px]. The fair
  /// background figure for a warp that treats the subject differently.
  double visible_background_jitter_px = NAN;
  /// The visible background's largest jump: per frame, the median over
  /// the points visible on it and the frame before of their step in the
  /// output; the largest over frames [output px]. NaN without such points.
  double visible_background_max_step_px = NAN;
  /// Straightness of straight background lines (world great circles) in
  /// the output, where visible: the largest distance of a line's points
  /// from their fitted line over all lines and frames [output px], and the
  /// frame where it happened. A global warp keeps them straight (~0).
  double line_deviation_px = 0.0;
  int line_deviation_frame = -1;
  /// The 99th percentile of the same deviation over every (line, frame)
  /// visible run [output px].
  double line_deviation_p99_px = 0.0;
  /// Hand-overs without jumps. kMesh with a background mesh: the largest
  /// per-frame step of any vertex's offset from the background layer, and
  /// the largest second difference (a jump shows as both; steady motion
  /// only in the first) [output px]. NaN otherwise.
  double blend_max_step_px = NAN, blend_max_accel_px = NAN;
  /// The same for the true head centre in the output (what a viewer sees
  /// of the face's motion) and for the head target H, in output px, over
  /// frames with a value on this and the previous frame(s). NaN without.
  double head_max_step_px = NAN, head_max_accel_px = NAN;
  double head_target_max_step_px = NAN, head_target_max_accel_px = NAN;
  /// kMesh: cells' singular-value ratios over all frames: the worst, the
  /// 1st percentile (99 % of cells are at least this), and fold-overs.
  double min_cell_ratio = 1.0, p01_cell_ratio = 1.0;
  int min_cell_ratio_frame = -1;
  int folded_cells = 0;
  /// kMesh with a background mesh: high-pass RMS of the band vertices'
  /// offsets from the background layer, in output px, mean over vertices
  /// in the band on >= half of the frames (NaN without such vertices).
  double band_jitter_px = NAN;
  /// The rotation the stabilizer used against the truth (kPose, kComposite,
  /// kMesh with its rows): the RMS over consecutive frames of the error of
  /// the camera's frame-to-frame rotation at the middle row [deg], the same
  /// at the input's focal length [input px], and the largest [deg]. NaN for
  /// other warps.
  double rotation_error_deg = NAN, rotation_error_px = NAN;
  double rotation_error_max_deg = NAN;
  /// Within ScorecardOptions' window (an IMU dropout): the head's and the
  /// visible background's jitter on the window's frames (each trajectory
  /// high-passed whole, its RMS taken over the window) [output px]. The
  /// virtual pose's largest per-frame step (kMesh: the scene layer's)
  /// within edge_s after each edge of the window (the hand-overs), and the
  /// 95th percentile of its steps on the other frames, at the output's
  /// focal length [output px]. NaN without a window (and for warps with no
  /// virtual pose).
  double window_head_jitter_px = NAN, window_background_jitter_px = NAN;
  double window_start_step_px = NAN, window_end_step_px = NAN;
  double virtual_step_p95_px = NAN;
  /// Per-stage time, median and p99 [ms].
  std::vector<std::pair<std::string, std::pair<double, double>>> stage_ms;
};

struct ScorecardOptions {
  /// High-pass cut-off for jitter [Hz].
  double highpass_hz = 0.5;
  /// A window of the sequence scored on its own [s from the start]; NaN:
  /// none (Score::window_*).
  double window_start_s = NAN, window_end_s = NAN;
  /// How long after each edge of the window a hand-over is looked for [s].
  double edge_s = 0.5;
};

/// Evaluates any stabilizer's per-frame warps against a simulated
/// sequence's ground truth (the true head centre and true far-background
/// directions, mapped through each frame's warp).
class Scorecard {
 public:
  /// `model` and `output` describe kPose warps (the stabilizer's camera and
  /// output geometry); `output_width/height` is the output image size of
  /// every method (for kIdentity: the input size).
  Scorecard(const sim::Simulator& sim, const CameraModel& model,
            const OutputGeometry& output, const ScorecardOptions& options);

  /// Adds frame `index` of the sequence with the warp applied to it.
  void Add(int index, const FrameWarp& warp);

  Score Compute() const;

  /// Trajectories for plots: per added frame, the stamp [s], the true head
  /// centre in the input and in the output [px] (NaN when out of view), and
  /// the first background point in the output.
  struct Sample {
    double t = 0.0;
    Eigen::Vector2d head_in, head_out, background_out;
    bool head_valid = false;
    double virtual_angle[3] = {0, 0, 0};  // rotation vector of R_v (rad)
    double real_angle[3] = {0, 0, 0};     // rotation vector of R_r (rad)
    Eigen::Vector2d offset = Eigen::Vector2d::Zero();  // t
    double crop_ratio = NAN, crop_need = NAN;          // FrameWarp's
  };
  const std::vector<Sample>& samples() const { return samples_; }

  /// Liu et al. stability of a 2D trajectory's frame-to-frame motion.
  static double Stability(const std::vector<Eigen::Vector2d>& x);
  /// The longest run of finite samples (jitter needs a contiguous series).
  static std::vector<Eigen::Vector2d> LongestFiniteRun(const std::vector<Eigen::Vector2d>& x);

 private:
  // Add's pieces: the visible background and the straight lines; a mesh's
  // cells and its offsets from the background layer; the warp's
  // distortion at the output centre; whether any output pixel is
  // undefined (and, for a pose warp, its angles and offset into *s); the
  // stage times.
  void AddVisibleBackground(int index, const FrameWarp& w);
  void AddMesh(int index, const FrameWarp& w);
  double CentreDistortion(const FrameWarp& w) const;
  bool Undefined(const FrameWarp& w, Sample* s) const;
  void AddStageTimes(const FrameWarp& w);
  // The true and the used middle-row rotation, and the virtual pose.
  void AddRotation(const sim::SimTruth& truth, const FrameWarp& w);
  // The output's and the input's roll against the true gravity.
  void AddRoll(const sim::SimTruth& truth, const FrameWarp& w);
  // Compute's pieces: the background figures (trajectories scored on runs
  // of at least min_run frames) and the lines', cells' and steps' figures.
  void ComputeBackground(double fps, size_t min_run, double diag, Score* sc) const;
  void ComputeMeshFigures(double fps, Score* sc) const;
  // The crop kept: mean and least width, its steps and second difference.
  void ComputeCrop(bool pose, Score* sc) const;
  // The rotation's error against the truth, and the window's figures.
  void ComputeRotationError(Score* sc) const;
  void ComputeBackgroundSteps(Score* sc) const;
  void ComputeWindow(double fps, Score* sc) const;
  bool MapToOutput(const FrameWarp& w, const Eigen::Vector2d& in_px,
                   Eigen::Vector2d* out_px) const;
  // kComposite: whether the subject, placed by the subject layer, covers
  // output pixel `out_px` of frame `index`.
  bool CompositeCovers(int index, const FrameWarp& w, const Eigen::Vector2d& out_px) const;

  const sim::Simulator& sim_;
  const CameraModel model_;
  const OutputGeometry output_;
  const ScorecardOptions options_;
  // The frame being added: the output geometry at its crop, its boundary.
  OutputGeometry frame_output_;
  ProtrusionGeometry frame_protrusion_;
  std::vector<double> kept_width_;  // per frame, 1 - 2 r (a homography: 1 / its scale)
  std::vector<double> output_roll_, input_roll_;  // per frame [rad]
  std::vector<Eigen::Vector3d> background_dirs_;
  std::vector<Eigen::Vector3d> visible_dirs_;
  std::vector<std::vector<Eigen::Vector2d>> visible_out_;  // [point][frame]
  // Straight world lines: sample directions per line.
  std::vector<std::vector<Eigen::Vector3d>> lines_;
  double line_dev_ = 0.0;
  int line_dev_frame_ = -1;
  std::vector<double> line_devs_;
  // The head target in output px per frame (NaN without one).
  std::vector<Eigen::Vector2d> head_target_out_;
  std::vector<double> cell_ratios_;
  double min_ratio_ = 1.0;
  int min_ratio_frame_ = -1;
  int folded_ = 0;
  std::vector<std::vector<Eigen::Vector2d>> band_offsets_;  // [vertex][frame]
  std::vector<int> band_frames_;
  std::vector<Sample> samples_;
  std::vector<std::vector<Eigen::Vector2d>> background_out_;  // [point][frame]
  std::vector<Eigen::Vector2d> head_out_;
  std::vector<bool> head_valid_;
  std::vector<double> distortion_;
  int undefined_ = 0;
  bool identity_ = true;
  std::vector<std::pair<std::string, std::vector<double>>> stages_;
  // Per frame (kPose, kComposite, kMesh; empty otherwise): the true and the
  // used world -> camera rotation at the middle row, and R_v (kMesh: R_b).
  std::vector<Eigen::Quaterniond> true_middle_, used_middle_, virtual_;
};

}  // namespace eval
}  // namespace steadiface
