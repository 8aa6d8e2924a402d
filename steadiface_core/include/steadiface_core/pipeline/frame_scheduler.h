#pragma once

#include <cstddef>
#include <deque>
#include <optional>
#include <utility>

#include "steadiface_core/common/time.h"
#include "steadiface_core/gyro/orientation_timeline.h"

namespace steadiface {

/// What happens to a frame whose last row the gyro did not cover within
/// max_gyro_wait_s.
enum class LateFramePolicy {
  kExtrapolate,  ///< process it with the gyro extrapolated past its newest sample
  kDrop,         ///< drop it
};

/// The stream's rules (the ROS keys of the same names, without the unit).
struct FrameSchedulerOptions {
  /// The longest a frame waits for the gyro to cover its last row, on the
  /// receive clock [s].
  double max_gyro_wait_s = 0.1;
  /// What happens to a frame whose wait ran out.
  LateFramePolicy late_frame_policy = LateFramePolicy::kExtrapolate;
  /// Frames that may wait at once [frames]; a burst beyond drops the oldest.
  int frame_queue_size = 10;
  /// No gyro sample for this long before a frame's stamp: the frame passes
  /// through unstabilized (or is dropped), and the IMU counts as lost [s].
  double imu_timeout_s = 1.0;
  /// A gap between gyro samples longer than this is reported [s].
  double imu_gap_warn_s = 0.05;
  /// Pipelined rendering: the longest a processed frame waits for the next
  /// one before it is published anyway, on the receive clock [s].
  double pipeline_hold_s = 0.1;
  /// A stamp this far behind the newest of its stream (image or gyro) is a
  /// jump of the clock backwards (a bag replayed in a loop): everything
  /// restarts [s].
  double time_jump_s = 1.0;
};

/// What to do with a frame the scheduler released, once its image is
/// known to be usable.
enum class FrameDisposition {
  kProcess,      ///< the gyro covers it: stabilize
  kExtrapolate,  ///< late, policy kExtrapolate: stabilize on extrapolated gyro
  kDropLate,     ///< late, policy kDrop
  kNoImu,        ///< no gyro within imu_timeout_s: pass through (or drop)
};

/// The stream's order, ROS-free: which frame is processed when.
///  - Gyro samples are taken at once; a bounded copy of the newest is kept
///    to replay into a rebuilt pipeline.
///  - A frame waits in a bounded FIFO until the gyro covers its last row or
///    its wait runs out (then the late-frame policy decides).
///  - A stamp not after the previous frame's is refused; a stamp that jumps
///    backwards (images or gyro) asks the owner to restart.
/// `Frame` is the owner's payload (the ROS layer's image and camera_info
/// messages). Times: stamps are the sensors' clock; `now` and `received`
/// are the owner's receive clock, where nullopt means "no clock" (the IMU
/// callback), so no wait runs out. Not thread-safe: one owner thread.
template <typename Frame>
class FrameScheduler {
 public:
  struct Queued {
    Frame frame;
    Time stamp;     ///< the frame's stamp (its first row, sensor clock)
    Time received;  ///< when it arrived (receive clock)
  };
  /// A frame released for processing; `late` when the gyro does not cover it.
  struct Released {
    Queued queued;
    bool late = false;
  };
  enum class Admission {
    kQueued,
    kQueuedDroppedOldest,  ///< queued; the queue was full, its oldest dropped
    kOldStamp,             ///< refused: not after the previous frame's stamp
  };

  explicit FrameScheduler(const FrameSchedulerOptions& options) : options_(options) {}

  const FrameSchedulerOptions& options() const { return options_; }

  /// True when a gyro sample stamped `stamp` jumped backwards by more than
  /// time_jump_s: the owner resets its pipeline and calls Reset().
  bool IsGyroTimeJump(Time stamp) const {
    return have_gyro_ && stamp + FromSeconds(options_.time_jump_s) < last_gyro_stamp_;
  }
  /// The gap before a sample stamped `stamp` when longer than
  /// imu_gap_warn_s, else 0 [s].
  double GyroGap(Time stamp) const {
    if (!have_gyro_ || stamp <= last_gyro_stamp_) return 0.0;
    const double gap = ToSeconds(stamp - last_gyro_stamp_);
    return gap > options_.imu_gap_warn_s ? gap : 0.0;
  }
  /// A sample the timeline accepted: the newest stamp, and the replay copy,
  /// bounded to the newest `keep` and `max_samples`.
  void OnGyroAccepted(const GyroSample& g, Duration keep, std::size_t max_samples) {
    if (!have_gyro_ || g.stamp > last_gyro_stamp_) {
      last_gyro_stamp_ = g.stamp;
      have_gyro_ = true;
    }
    recent_gyro_.push_back(g);
    while (!recent_gyro_.empty() && (recent_gyro_.back().stamp - recent_gyro_.front().stamp > keep ||
                                     recent_gyro_.size() > max_samples)) {
      recent_gyro_.pop_front();
    }
  }

  /// True when a frame stamped `stamp` jumped backwards by more than
  /// time_jump_s from the last processed frame: the owner restarts.
  bool IsFrameTimeJump(Time stamp) const {
    return have_last_frame_ && stamp + FromSeconds(options_.time_jump_s) < last_frame_stamp_;
  }
  /// Queues a frame, refusing one not after the newest queued (or, with
  /// none queued, the last processed) and bounding the queue.
  Admission Admit(Frame frame, Time stamp, Time received) {
    const bool have_newest = !queue_.empty() || have_last_frame_;
    const Time newest = queue_.empty() ? last_frame_stamp_ : queue_.back().stamp;
    if (have_newest && stamp <= newest) return Admission::kOldStamp;
    Admission a = Admission::kQueued;
    if (queue_.size() >= static_cast<std::size_t>(options_.frame_queue_size)) {
      queue_.pop_front();
      a = Admission::kQueuedDroppedOldest;
    }
    queue_.push_back({std::move(frame), stamp, received});
    return a;
  }

  /// The oldest waiting frame, or null.
  const Queued* Front() const { return queue_.empty() ? nullptr : &queue_.front(); }
  /// Drops the oldest waiting frame (its geometry cannot be used).
  void DropFront() {
    if (!queue_.empty()) queue_.pop_front();
  }
  /// Releases the oldest frame when `covered` (the gyro covers its last
  /// row), its wait ran out by `now`, or at the end of input (`flush`);
  /// else nullopt, and the frames behind it wait too (FIFO).
  std::optional<Released> ReleaseFront(bool covered, std::optional<Time> now, bool flush) {
    if (queue_.empty()) return std::nullopt;
    if (!covered && !flush && !WaitedOut(queue_.front().received, now, options_.max_gyro_wait_s)) {
      return std::nullopt;
    }
    Released r{std::move(queue_.front()), !covered};
    queue_.pop_front();
    return r;
  }
  /// What to do with a released frame, stamped `stamp`, whose image is
  /// usable: no recent gyro first, then the late-frame policy.
  FrameDisposition Dispose(Time stamp, bool late) const {
    if (!have_gyro_ || ToSeconds(stamp - last_gyro_stamp_) > options_.imu_timeout_s) {
      return FrameDisposition::kNoImu;
    }
    if (!late) return FrameDisposition::kProcess;
    return options_.late_frame_policy == LateFramePolicy::kDrop ? FrameDisposition::kDropLate
                                                                : FrameDisposition::kExtrapolate;
  }
  /// Pipelined: whether a processed frame received at `received` has waited
  /// its pipeline_hold for the next one by `now` (always at `flush`).
  bool HoldRanOut(Time received, std::optional<Time> now, bool flush) const {
    return flush || WaitedOut(received, now, options_.pipeline_hold_s);
  }

  /// A frame went out (stabilized or passed through): later ones must be
  /// stamped after it.
  void OnFrameDone(Time stamp) {
    last_frame_stamp_ = stamp;
    have_last_frame_ = true;
  }
  /// The pipeline was rebuilt: the next frame starts a new sequence.
  void ForgetLastFrame() { have_last_frame_ = false; }
  /// The clock jumped backwards: forget every frame, every stamp and the
  /// replay copy.
  void Reset() {
    queue_.clear();
    recent_gyro_.clear();
    have_last_frame_ = false;
    have_gyro_ = false;
  }

  /// The newest accepted gyro samples, oldest first (bounded).
  const std::deque<GyroSample>& recent_gyro() const { return recent_gyro_; }
  bool have_gyro() const { return have_gyro_; }
  /// The newest accepted gyro stamp (meaningful when have_gyro()).
  Time last_gyro_stamp() const { return last_gyro_stamp_; }
  std::size_t queued() const { return queue_.size(); }

 private:
  static bool WaitedOut(Time since, std::optional<Time> now, double wait_s) {
    return now && *now >= since && ToSeconds(*now - since) >= wait_s;
  }

  const FrameSchedulerOptions options_;
  std::deque<Queued> queue_;               // bounded by frame_queue_size
  std::deque<GyroSample> recent_gyro_;     // bounded by OnGyroAccepted's limits
  Time last_frame_stamp_{};
  bool have_last_frame_ = false;
  Time last_gyro_stamp_{};
  bool have_gyro_ = false;
};

}  // namespace steadiface
