#pragma once

#include <cmath>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "steadiface_core/composite/compositor.h"
#include "steadiface_core/eval/ffmpeg_baseline.h"
#include "steadiface_core/layered/layer_blend.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/motion.h"

namespace steadiface {
namespace eval {

/// The view's settings an evaluation overrides (NaN, -1 or empty: the
/// package's default).
struct ViewOverrides {
  /// output.crop: -1 the default, 0 fixed, 1 dynamic.
  int crop_mode = -1;
  /// output.horizon: off, level or lock; empty: the default.
  std::string horizon;
  /// horizon.level_weight, horizon.lock_weight [-].
  double level_weight = NAN, lock_weight = NAN;
  /// horizon.level_tolerance [deg].
  double level_tolerance_deg = NAN;
  /// horizon.warmup, horizon.time_constant [s].
  double gravity_warmup_s = NAN, gravity_tau_s = NAN;
  /// output.dynamic.widest_crop_ratio [-].
  double widest = NAN;
  /// output.dynamic.start_wide false.
  bool start_tight = false;
  /// output.dynamic.shake_path_hz [Hz], output.dynamic.headroom [-].
  double shake_hz = NAN, headroom = NAN;
  /// output.dynamic.max_widen_rate, max_tighten_rate [1/s] and
  /// max_widen_accel [1/s^2].
  double widen_rate = NAN, tighten_rate = NAN, zoom_accel = NAN;
};

/// Everything steadiface_evaluate runs: which presets and methods, the
/// simulated sequence, the options it changes from each method's defaults
/// (NaN: the default) and the extra files it writes.
struct EvaluationOptions {
  /// The simulator's photos and gyro logs (test/data).
  std::string data_dir;
  /// Where report.json, the trajectories and the extra files go.
  std::string out_dir;
  /// Simulator presets, in order; default: every one.
  std::vector<std::string> presets;
  /// Methods (MethodFromName's names, "<method>/video" for the approximate
  /// video scorer, ffmpeg-vidstab, ffmpeg-deshake); empty: none, gyro-only,
  /// steadiface, and the video-scored ones and ffmpeg's when it is there.
  std::vector<std::string> methods;
  /// Sequence length [s]; NaN: 3 s, or a recorded gyro trace's whole length.
  double duration_s = NAN;
  /// Frame size [px] and the simulator's seed.
  int width = 640, height = 360;
  uint64_t seed = 1;
  /// Render every output (scores the warps either way).
  bool render = false;

  /// The recorded trace's rotation scale and playback speed [-].
  double gyro_scale = NAN, gyro_speed = NAN;
  /// The subject's distance [m].
  double head_distance_m = NAN;
  /// The head's own motion against the scene scaled by this (bob, sway,
  /// yaw, pitch, lean and drift amplitudes; the preset's frequencies) [-],
  /// and its 2-8 Hz jitter by head_jitter_scale [-]: stress tests beyond
  /// the presets.
  double head_motion_scale = NAN;
  double head_jitter_scale = NAN;
  /// The head's yaw amplitude instead of the preset's [rad] (then scaled by
  /// head_motion_scale), and its turns' frequency times this [-]: fast
  /// turns, a head shaking "no".
  double head_yaw_rad = NAN;
  double head_turn_speed = NAN;
  /// The simulated head: "relief" (the photo on an ellipsoid with a nose,
  /// the simulator's default), "mean-face" (that relief with the mean 3D
  /// face's depths at the photo's landmarks, kMeanFaceHeadBreadth broad) or
  /// "flat" (empty: the simulator's default).
  std::string head_model;
  /// The mean-face head's breadth unless head_breadth sets it [face widths].
  static constexpr double kMeanFaceHeadBreadth = 1.1;
  /// The relief head's breadth [face widths] (NaN: the simulator's; see
  /// sim::HeadReliefOptions::breadth_face_widths).
  double head_breadth = NAN;

  /// output.crop_ratio [-].
  double crop = NAN;
  /// face.search_interval [s].
  double search_interval_s = NAN;
  /// rotation_source: auto (the package's default), imu or visual.
  RotationSource rotation_source = RotationSource::kAuto;
  /// A window of each sequence scored on its own (start, end) [s]; NaN: the
  /// simulated IMU's dropout, if any.
  Eigen::Vector2d window_s = Eigen::Vector2d::Constant(NAN);
  /// head.w_stay [-] and head.d_ref [fraction of the width].
  double head_w_stay = NAN, head_d_ref = NAN;
  /// stabilizer.intentional_window_s: E_r C0 follows the camera's mean
  /// rotation rate over this trailing window [s]; 0 = the paper's term.
  double intentional_window_s = NAN;
  /// The ffmpeg peers' settings (their defaults unless set).
  FfmpegPeerOptions peer;
  /// terms.protrusion_alpha_face: E_p's tolerance while a face is fitted
  /// [fraction of the width].
  double protrusion_alpha_face = NAN;
  /// dynamic.pose_pivot_depth: the pose-invariant head centre [face scales].
  double pose_pivot_depth = NAN;
  /// stabilizer.subject_reach [jaw widths] (0: off), its low-pass [Hz] and hold.
  double subject_reach = 0.0, reach_lowpass_hz = NAN, reach_hold = NAN;
  /// Added to imu/time_offset and camera/readout_time [s] (calibration
  /// studies: a deliberately wrong IMU timing).
  double offset_error_s = 0.0, readout_error_s = 0.0;
  /// The layered warp's blend and the composite's options, as given.
  LayerBlendOptions blend;
  CompositeOptions composite;
  ViewOverrides view;

  /// Also feasible_<preset>_<method>.csv (and _roll.csv with a roll [rad] > 0).
  bool feasible_set = false;
  double feasible_roll = 0.0;
  /// Layered: also reach_<preset>_<method>.csv.
  bool reach_tube = false;
  /// Composite: every 15th frame's pictures (composite_<preset>_*.png).
  bool composite_frames = false;
  /// Diagnostic: the stabilizer is handed the simulator's true head centre
  /// in place of the tracker's pose-invariant centre on every frame with a
  /// face (Pipeline::SetTrueHeadCentre): what a perfect tracker would give.
  bool true_head = false;
  /// >= 0: <preset>_<method>_frame.png and _average15.png around that frame.
  int average_at = -1;
};

/// Applies the overrides to one method's pipeline options; an unknown
/// horizon mode is an error.
Status ApplyViewOverrides(const ViewOverrides& view, PipelineOptions* options);

/// The simulated head's own motion against the scene (bob, sway, yaw,
/// pitch, lean, drift) k times the preset's, and its 2-8 Hz jitter j times
/// (NaN: as the preset has them); negative factors are refused
/// (`--head-motion`, `--head-jitter`).
Status ScaleHeadMotion(double k, double j, sim::HeadMotionOptions* head);

/// The simulated head's yaw amplitude set to `yaw_rad` and its turns'
/// frequency scaled by `speed` (NaN: as the preset has them); out of range
/// is refused (`--head-yaw`, `--head-turn-speed`).
Status SetHeadTurn(double yaw_rad, double speed, sim::HeadMotionOptions* head);

/// Runs every preset with every method and scores each against the
/// simulator's truth. Prints one markdown row per (preset, method) to `out`
/// (and the composite's quality table when a composite ran), writes
/// report.json, traj_<preset>_<method>.csv and the extra files under
/// out_dir, and reports failures to `err`. Returns the process's exit
/// status: 0 all ran, 1 some failed, 2 a method is unknown or needs ffmpeg.
int RunEvaluation(const EvaluationOptions& options, std::ostream& out, std::ostream& err);

}  // namespace eval
}  // namespace steadiface
