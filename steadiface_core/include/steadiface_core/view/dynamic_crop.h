#pragma once

#include <deque>
#include <string>

#include "steadiface_core/common/status.h"

namespace steadiface {

/// How the output's crop is chosen.
enum class CropMode {
  kFixed,    ///< output.crop_ratio on every frame (the paper's r)
  kDynamic,  ///< follows the margin the motion needs (DynamicCrop)
};

/// "fixed" | "dynamic".
Status ParseCropMode(const std::string& name, CropMode* mode);
const char* CropModeName(CropMode mode);

/// The causal dynamic crop (output/crop: dynamic).
struct DynamicCropOptions {
  /// kFixed: output.crop_ratio on every frame. kDynamic: between
  /// widest_crop_ratio and output.crop_ratio, as the motion needs.
  CropMode mode = CropMode::kFixed;
  /// The widest view the dynamic crop opens to: its smallest crop ratio per
  /// side [-] (0.03 keeps 94 % of the width). In [0, 0.4]; above
  /// output.crop_ratio it acts as output.crop_ratio (the crop stays fixed).
  double widest_crop_ratio = 0.03;
  /// The crop is held at headroom x the largest margin the shake of the
  /// last memory_s asked for, plus `extra`, and at least at the largest
  /// margin the solved poses asked for, plus `extra` [-]. >= 1.
  double headroom = 1.5;
  /// Added to the margins asked for [crop ratio, -]. In [0, 0.2].
  double extra = 0.01;
  /// How long a margin asked for is remembered [s]: the crop widens only
  /// after this long without a need for it. In [0.1, 30].
  double memory_s = 3.0;
  /// Widening (the view opening when the motion calms): fastest rate
  /// [crop ratio per s] and largest change of that rate [per s^2]. Slow:
  /// a zoom is motion of everything off the centre, so the view opens over
  /// seconds (0.12 of the crop ratio in about 14 s).
  double max_widen_rate = 0.01;
  double max_widen_accel = 0.002;
  /// Tightening (room for growing motion, before the protrusion search has
  /// to give way): fastest rate [per s] and largest change of it [per s^2].
  double max_tighten_rate = 0.15;
  double max_tighten_accel = 0.3;
  /// The shake the crop makes room for: the real camera's distance from its
  /// path low-passed at this frequency [Hz] (ShakePath). In [0.05, 10].
  double shake_path_hz = 0.7;
  /// Start (and restart after a time jump) at the widest view rather than
  /// at the fixed crop.
  bool start_wide = true;
};

/// Checks `options` (each field's range).
Status ValidateDynamicCropOptions(const DynamicCropOptions& options);

/// The dynamic crop's state after a frame.
struct CropReport {
  /// The crop is dynamic (CropMode::kDynamic).
  bool dynamic = false;
  /// The crop ratio the frame was made with [-] (kept width 1 - 2 r).
  double crop_ratio = 0.0;
  /// The margins this frame asked for (CropNeed) [-], 0 with the fixed
  /// crop: the shake's (the real camera against its low-passed path,
  /// ShakePath), and the solved poses' (what the solve asked for before the
  /// protrusion search held it in: the face held, the background layer).
  double shake_need = 0.0;
  double solved_need = 0.0;
  /// Where the crop is heading: max(headroom x the remembered shake need,
  /// the remembered solved need) + extra, within [widest, tightest] [-].
  double target = 0.0;
};

/// A crop that widens when the recent motion needs little margin and
/// tightens before the protrusion search has to give way, with its rate and
/// its rate's change bounded. Causal: the next frame's crop comes from the
/// needs of the frames before it. Starts at the tightest (the fixed crop)
/// or, with start_wide, at the widest.
/// Its memory holds at most one entry per frame of `memory_s` (and never
/// more than 4096). Not thread-safe.
class DynamicCrop {
 public:
  /// `options` validated (ValidateDynamicCropOptions); `tightest` is
  /// output.crop_ratio.
  DynamicCrop(const DynamicCropOptions& options, double tightest);

  /// The crop ratio for the next frame.
  double crop_ratio() const { return r_; }
  /// Takes the frame's needs (CropReport) at time `t_s` [s] and moves the
  /// crop for the next frame. Returns the report of the frame just made
  /// (its crop ratio, needs and the target now).
  CropReport Update(double t_s, double shake_need, double solved_need);
  /// Forgets the needs and the time (a time jump); the crop stays where it is.
  void Reset();

 private:
  double Target(double t_s, double shake_need, double solved_need);

  const DynamicCropOptions options_;
  const double tightest_;
  const double widest_;  // min(widest_crop_ratio, tightest)
  double r_ = 0.0;       // crop ratio for the next frame
  double rate_ = 0.0;    // its rate of change [1/s]
  bool has_time_ = false;
  double last_t_ = 0.0;
  struct Need {
    double t_s, shake, solved;
  };
  std::deque<Need> needs_;
};

}  // namespace steadiface
