#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/gyro/orientation_timeline.h"

namespace steadiface {

/// One accelerometer reading as the IMU reports it.
struct AccelSample {
  /// Stamp on the IMU's clock.
  Time stamp;
  /// Specific force in the IMU frame [m/s^2] (at rest: 1 g pointing up).
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();
};

/// How the virtual camera's roll is held against gravity.
enum class HorizonMode {
  kOff,    ///< the roll as the stabilizer makes it (the paper)
  kLevel,  ///< pulled towards the horizon within the crop's margin
  kLock,   ///< held at 0 (a tighter crop with output/crop dynamic)
};
Status ParseHorizonMode(const std::string& name, HorizonMode* mode);
const char* HorizonModeName(HorizonMode mode);

/// The level horizon (output/horizon).
struct HorizonOptions {
  HorizonMode mode = HorizonMode::kOff;
  /// Readings whose magnitude is more than this fraction off 1 g are not
  /// gravity (the robot or the hand accelerating) and are left out [-].
  /// In (0, 1].
  double gravity_tolerance = 0.1;
  /// The complementary filter's time constant [s]: gravity in the gyro's
  /// world frame follows the accepted readings this slowly (until that
  /// long has passed, their mean), so the gyro carries the orientation and
  /// the readings' noise and the hand's and the gait's accelerations (a few
  /// degrees at 1-3 Hz) average out; only the gyro's drift is followed.
  /// In [0.05, 60].
  double time_constant_s = 5.0;
  /// The estimate's second stage: a critically damped low-pass at this
  /// frequency [Hz]. The running mean of a hand's 1-3 Hz accelerations
  /// wobbles at their frequency by their tilt over 2 pi f T; this takes
  /// that out of the roll the output is levelled to. In [0.01, 10].
  double lowpass_hz = 0.15;
  /// Gravity is trusted once accepted readings span this long [s] (and
  /// number at least 10): their mean by then is steady enough not to roll
  /// the output as it settles. In [0, 60].
  double warmup_s = 0.3;
  /// Weights of the horizon term E_h (the sine of the roll against
  /// gravity beyond level_tolerance_deg, squared; HorizonCost) in the
  /// solve: `level` and `lock` [-]. Both below the face term's
  /// w_f (stabilizer weights.fit, 100), so where the two conflict the face
  /// wins; `lock` holds the roll mostly by measuring E_d and E_o against
  /// the real camera turned level, which leaves the face its term.
  double level_weight = 4.0;
  double lock_weight = 50.0;
  /// `level` leaves a roll within this of the estimated horizon alone [deg]:
  /// the estimate's own error on a hand-held or a legged robot's camera, a
  /// mean of readings the hand's and the gait's accelerations disturb, is
  /// up to about 0.7 deg in its first seconds (docs/evaluation.md, "The
  /// level horizon's tolerance"), and pulling within it would roll a
  /// nearly still view after that error. `lock` holds 0. In [0, 10].
  double level_tolerance_deg = 1.0;
};

Status ValidateHorizonOptions(const HorizonOptions& options);

/// The standard gravity [m/s^2].
constexpr double kStandardGravity = 9.80665;

/// Gravity in the gyro's world frame from the accelerometer, with a
/// complementary filter against the gyro: each accepted reading is turned
/// into the world frame by the timeline's orientation at its time, and the
/// estimate follows those with `time_constant_s`. Readings far from 1 g,
/// non-finite or not yet covered by the gyro are left out (counted).
/// Not thread-safe.
class GravityEstimator {
 public:
  explicit GravityEstimator(const HorizonOptions& options)
      : options_(options) {}

  /// Takes a reading already in the camera frame (R_cam_imu applied), at
  /// camera-clock time `t`. Returns true when it was accepted.
  bool Add(Time t, const Eigen::Vector3d& a_cam,
           const OrientationTimeline& timeline);
  /// Gravity is known (warmup_s of accepted readings since the last reset).
  bool valid() const {
    return accepted_ >= 10 &&
           ToSeconds(last_t_ - first_t_) >= options_.warmup_s;
  }
  /// The unit "up" (against gravity) in the gyro's world frame (after the
  /// low-pass).
  Eigen::Vector3d up_world() const { return smooth_.normalized(); }
  uint64_t accepted() const { return accepted_; }
  uint64_t rejected() const { return rejected_; }
  /// Forgets the estimate (the timeline was reset: a new world frame).
  void Reset();

 private:
  const HorizonOptions options_;
  Eigen::Vector3d up_ = Eigen::Vector3d(0.0, -1.0, 0.0);  // first stage
  Eigen::Vector3d smooth_ = up_, smooth_rate_ = Eigen::Vector3d::Zero();
  bool has_time_ = false;
  Time first_t_, last_t_;
  uint64_t accepted_ = 0, rejected_ = 0;
};

/// The roll of a camera against the horizon: the angle, about its optical
/// axis, from the image's "up" (-y) to gravity's "up" `up_cam` seen in that
/// camera [rad]; positive when the horizon appears turned clockwise.
double HorizonRoll(const Eigen::Vector3d& up_cam);

}  // namespace steadiface
