#pragma once

#include "steadiface_core/common/status.h"
#include "steadiface_core/stabilizer/head_smoother.h"

namespace steadiface {

/// Base weights of the objective (paper Eq. 5). Dynamic adjustment scales
/// them per frame; the weights in effect are reported with every frame.
struct StabilizerWeights {
  /// w_f: landmark fitting E_f [-].
  double fit = 100.0;
  /// w_d: distortion E_d [-].
  double distortion = 200.0;
  /// w_o: rotation following E_o [-].
  double follow = 0.5;
  /// w_r,C0: rotation smoothness, C0 part of E_r [-].
  double rotation_c0 = 10.0;
  /// w_r,C1: rotation smoothness, C1 part of E_r [-]. Heavier than this
  /// carries the virtual camera's momentum past the real camera's swings on
  /// strong shake (running), so gyro-only overshoots them.
  double rotation_c1 = 10.0;
  /// w_t,C0: principal offset smoothness, C0 part of E_t [-].
  double translation_c0 = 20.0;
  /// w_t,C1: principal offset smoothness, C1 part of E_t [-].
  double translation_c1 = 80.0;
  /// w_p: protrusion E_p [-].
  double protrusion = 1.0;
};

/// Shapes of individual terms.
struct TermOptions {
  /// E_d: angle between virtual and real camera below which the logistic
  /// makes the penalty ~0 [rad]. About what the default 15 % crop admits at
  /// its edges; lower, E_d drags the virtual camera along the running shake
  /// before the crop is used up.
  double distortion_threshold_rad = 0.15;
  /// E_d: logistic slope [1/rad].
  double distortion_slope = 150.0;
  /// E_p: α, the tolerated protrusion [normalized units, fraction of width],
  /// where no face is fitted (gyro-only poses, the layered background
  /// layer, and a lost face's w_f fading out after its held face is let go).
  double protrusion_alpha = 0.002;
  /// E_p: α while E_f holds a face at its full weight [fraction of width];
  /// between the two in proportion to w_f / weights.fit (ProtrusionAlpha).
  /// Against the stiff fit term a wall as stiff as protrusion_alpha stops
  /// the solve short of both: at a 0.85 crop on `vlog` one frame's face
  /// was held 12 px off its target with E_p at 0.
  double protrusion_alpha_face = 0.02;
  /// E_p: the real boundary is shrunk by this on every side before measuring
  /// protrusion [fraction of width].
  double protrusion_shrink = 0.005;
  /// E_p: boundary samples per output edge [count].
  int protrusion_samples_per_edge = 8;
};

/// E_p's α for a frame whose fitting weight is `fit_weight` out of the
/// nominal `nominal_fit` (weights.fit): protrusion_alpha at 0, rising
/// linearly to protrusion_alpha_face at the nominal weight and above.
double ProtrusionAlpha(const TermOptions& terms, double fit_weight, double nominal_fit);

/// Dynamic weight adjustment (paper §4.4). Every factor moves towards its
/// target with the time constant `fade_time_s`, so weights never jump.
struct DynamicWeightOptions {
  /// Master switch; off = base weights (and no face = w_f 0) only.
  bool enabled = true;
  /// Time constant of every weight change, including the fade in/out of w_f
  /// when the face appears or is lost [s].
  double fade_time_s = 0.25;
  /// A face back after a loss (E_f fitted the held face meanwhile) jumps
  /// by the head's own motion during the loss; it is shifted back onto the
  /// held face and rejoins its landmarks with this time constant instead
  /// of pulling the camera in one frame; 0 = at once [s].
  double handback_time_s = 0.1;
  /// Window of the mean |omega| [s].
  double gyro_window_s = 0.5;
  /// Mean |omega| at or below which the camera counts as still [rad/s].
  double gyro_still_rad_s = 0.015;
  /// Mean |omega| at or above which w_f is at full strength [rad/s].
  double gyro_active_rad_s = 0.06;
  /// w_f scale for a still camera [-] (0 = the virtual camera ignores the
  /// face when the camera is still).
  double gyro_still_fit_scale = 0.0;
  /// |yaw| or |pitch| at which w_f starts to drop [rad].
  double pose_low_rad = 0.35;
  /// |yaw| or |pitch| at which w_f reaches pose_min_fit_scale [rad].
  double pose_high_rad = 0.7;
  /// w_f scale at large head pose [-].
  double pose_min_fit_scale = 0.1;
  /// Smoothness weights are multiplied by (1 + boost) at large head pose [-].
  double pose_smoothness_boost = 3.0;
  /// The pose-invariant head centre (ours; the paper's §4.4 names the
  /// problem, "the 2D landmark center is not pose-invariant"): a head turns
  /// about its skull's centre, this far behind the landmarks' centre, so the
  /// landmarks are moved back by that depth times sin(yaw) before E_f and
  /// Eq. 1 read them [face scales: the landmarks' RMS distance to their
  /// centre]. 0 = off (the paper's landmark centre). The default is what
  /// removes most of a turning relief head's swing in the simulator (a
  /// 0.09 m deep turning centre; PnP's yaw reads 0.88 of the true one).
  double pose_pivot_depth = 1.5;
  /// Time constant of the causal low-pass on the yaw that moves the
  /// landmarks: the pose from PnP is noisier from frame to frame than the
  /// landmarks' centre [s]. It holds while the head turns slowly; ...
  double pose_yaw_time_constant_s = 0.1;
  /// ... faster, the low-pass opens (a one-euro filter, Casiez et al.
  /// 2012): its cut-off rises by this many Hz per rad/s of the yaw's
  /// filtered speed above pose_yaw_speed_floor_rad_s, so a fast turn is
  /// not followed late (the 0.1 s low-pass lags a head shaken at 140 deg/s
  /// by 0.2 rad, its centre 0.3 face scales off) [Hz/(rad/s)]. 0 = a plain
  /// low-pass.
  double pose_yaw_speed_gain = 5.0;
  /// The yaw's speed below which the low-pass stays at its time constant,
  /// keeping PnP's frame-to-frame noise out (0.5 cost up to 10 % of head
  /// jitter on slow presets, docs/evaluation.md) [rad/s].
  double pose_yaw_speed_floor_rad_s = 0.8;
  /// The nod: a head also pitches about its skull's centre, and its
  /// landmarks move up and down by pose_pivot_depth times sin(pitch). They
  /// are moved back by this share of that, the nod being PnP's pitch (low-
  /// passed as the yaw is) above its slow mean. PnP's pitch is about as
  /// noisy as a walking head's nod (0.012-0.014 against 0.015 rad RMS
  /// above 0.5 Hz in the simulator), so less than the whole shift; 0 =
  /// off [-].
  double pose_nod_gain = 0.4;
  /// Time constant of the slow mean the nod is taken from: a head held
  /// tilted is not a nod, and PnP's pitch of a face is offset by the
  /// face's own proportions [s].
  double pose_nod_time_constant_s = 1.0;
  /// The nod's shift fades out between this |yaw| and twice it: a turned
  /// face's pitch from PnP is not its nod [rad].
  double pose_nod_max_yaw_rad = 0.15;
  /// Frames in the landmark-variation window [count].
  int variation_window = 10;
  /// RMS second difference of the gyro-compensated landmark centre at which
  /// w_f starts to drop [normalized units].
  double centre_variation_low = 0.004;
  /// ... and reaches variation_min_fit_scale [normalized units].
  double centre_variation_high = 0.015;
  /// RMS relative second difference of the face scale at which w_f starts to
  /// drop [-].
  double scale_variation_low = 0.03;
  /// ... and reaches variation_min_fit_scale [-].
  double scale_variation_high = 0.1;
  /// w_f scale for very noisy landmarks [-].
  double variation_min_fit_scale = 0.15;
};

/// Ceres settings of the per-frame solve.
struct SolverOptions {
  /// Iteration cap per frame [count]. The solve usually converges in 2-3
  /// iterations (as the paper says). Where the crop margin runs out, E_p is a
  /// stiff wall that LM slides along slowly: on strong shake (the shake
  /// preset) 193 of 294 solves did not converge in 10 iterations, 3 in 200;
  /// stopped early, the pose lags the head target by the unfinished step.
  /// max_time_s still bounds every solve.
  int max_iterations = 100;
  /// Relative cost change that ends the solve [-].
  double function_tolerance = 1e-6;
  /// Gradient tolerance [-].
  double gradient_tolerance = 1e-10;
  /// Wall-time cap per solve [s]. A cap that runs out before the solver's
  /// first step is taken as a stall and the solve is rerun under
  /// max_iterations alone (StallTolerantSolve).
  double max_time_s = 0.02;
};

/// Everything the stabilizer does per frame.
struct StabilizerOptions {
  HeadSmootherOptions head;
  StabilizerWeights weights;
  TermOptions terms;
  DynamicWeightOptions dynamic;
  SolverOptions solver;
  /// Binary-search steps between the solved and the real pose when the
  /// solution leaves undefined pixels (paper §4.4) [count].
  int protrusion_search_steps = 10;
  /// Rows at which R_r(y) is tabulated per frame [count].
  int row_rotation_samples = 32;
  /// Landmarks below this confidence are ignored (as "no face") [0-1].
  double min_face_confidence = 0.3;
  /// Gyro-only baseline: ignore faces entirely (w_f = 0).
  bool gyro_only = false;
  /// Also solve the background layer every frame: the same optimization
  /// without E_f (exactly the gyro-only pose) with its own smoothness state,
  /// the second virtual camera of a subject-aware warp. Off: one layer, as
  /// the paper (~0.1 ms per frame when on).
  bool background_layer = false;
  /// Where Eq. 1 reads the landmark centre C. true (ours): C is first mapped
  /// into the virtual view predicted from the virtual camera's own smooth
  /// motion (constant velocity from the last two frames); the real camera's
  /// rotation shake is then already removed from C, so H only has to filter
  /// the head's and the hand's translation. false: C in the real frame, as
  /// the paper writes it, so H also sees (and partly passes) the shake.
  bool smooth_head_in_virtual_view = true;
  /// E_r's C0 term pulls towards the previous virtual rotation moved by the
  /// camera's intentional rotation: its mean rate over this trailing window
  /// [s] (ours; removes the lag of the paper's C0 term during pans). 0 =
  /// the paper's term (towards the previous virtual rotation).
  double intentional_window_s = 0.0;
  /// With the background layer on: Eq. 1's H is held within this reach of
  /// where the background layer shows the face (a disc), in jaw widths of
  /// the face [-], so the offset between the layers at the head stays
  /// within what a transition band can absorb and the background layer is
  /// never moved by the face. The background layer is solved first. 0 =
  /// off (H is not constrained by the background layer).
  double subject_reach = 0.0;
  /// With subject_reach: H follows the slow part of where the background
  /// layer shows the face (the head's drift in the steady scene, as a
  /// viewer expects), low-passed at this frequency by a tracking loop that
  /// follows ramps without lag (TrackingLowpass), so the reach is spent on
  /// the face's fast motion rather than on its drift [Hz]. 0 = H is held
  /// within the reach of the face itself.
  double subject_reach_lowpass_hz = 0.2;
  /// With subject_reach_lowpass_hz: the fraction of the reach by which
  /// Eq. 1's H may stay away from that slow part (holding still against the
  /// drift); the rest of the reach is left for the face's fast motion [0-1].
  double subject_reach_hold = 0.5;
};

Status ValidateStabilizerWeights(const StabilizerWeights& weights);
Status ValidateStabilizerOptions(const StabilizerOptions& options);

}  // namespace steadiface
