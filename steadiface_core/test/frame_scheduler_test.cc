#include "steadiface_core/pipeline/frame_scheduler.h"

#include <cmath>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

namespace steadiface {
namespace {

using Scheduler = FrameScheduler<int>;
using Admission = Scheduler::Admission;

Time At(double seconds) { return Time(FromSeconds(seconds)); }

GyroSample Gyro(double seconds) {
  GyroSample g;
  g.stamp = At(seconds);
  g.angular_velocity = Eigen::Vector3d(0.1, 0.0, 0.0);
  return g;
}

// Feeds gyro at `rate_hz` over [from, to] s.
void FeedGyro(Scheduler* s, double from, double to, double rate_hz = 200.0) {
  const int n = static_cast<int>(std::lround((to - from) * rate_hz));
  for (int i = 0; i <= n; ++i) s->OnGyroAccepted(Gyro(from + i / rate_hz), FromSeconds(10.0), 100000);
}

TEST(FrameSchedulerTest, CoveredFramesAreReleasedAtOnceInOrder) {
  Scheduler s{FrameSchedulerOptions{}};
  FeedGyro(&s, 0.0, 1.0);
  std::vector<int> out;
  for (int i = 0; i < 5; ++i) {
    const Time stamp = At(0.1 + 0.033 * i);
    ASSERT_EQ(s.Admit(i, stamp, stamp), Admission::kQueued);
    const auto r = s.ReleaseFront(/*covered=*/true, std::nullopt, false);
    ASSERT_TRUE(r.has_value());
    EXPECT_FALSE(r->late);
    EXPECT_EQ(r->queued.stamp, stamp);
    EXPECT_EQ(s.Dispose(r->queued.stamp, r->late), FrameDisposition::kProcess);
    s.OnFrameDone(r->queued.stamp);
    out.push_back(r->queued.frame);
  }
  EXPECT_EQ(out, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(s.queued(), 0u);
}

TEST(FrameSchedulerTest, AnUncoveredFrameWaitsItsWaitAndHoldsTheOnesBehindIt) {
  FrameSchedulerOptions o;
  o.max_gyro_wait_s = 0.1;
  Scheduler s{o};
  FeedGyro(&s, 0.0, 1.0);
  s.Admit(1, At(1.0), At(2.0));
  s.Admit(2, At(1.033), At(2.033));
  // Not covered, no receive clock (the IMU callback): nothing runs out.
  EXPECT_FALSE(s.ReleaseFront(false, std::nullopt, false).has_value());
  // 99 ms after it arrived: still waiting, and the frame behind it too.
  EXPECT_FALSE(s.ReleaseFront(false, At(2.099), false).has_value());
  EXPECT_EQ(s.queued(), 2u);
  EXPECT_EQ(s.Front()->frame, 1);
  // A clock earlier than its arrival never runs a wait out.
  EXPECT_FALSE(s.ReleaseFront(false, At(1.5), false).has_value());
  // At 100 ms the wait has run out: released late.
  const auto r = s.ReleaseFront(false, At(2.1), false);
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->late);
  EXPECT_EQ(r->queued.frame, 1);
  EXPECT_EQ(s.Front()->frame, 2);
}

TEST(FrameSchedulerTest, TheLateFramePolicyDecidesWhatALateFrameBecomes) {
  for (const LateFramePolicy policy : {LateFramePolicy::kExtrapolate, LateFramePolicy::kDrop}) {
    FrameSchedulerOptions o;
    o.late_frame_policy = policy;
    Scheduler s{o};
    FeedGyro(&s, 0.0, 1.0);
    EXPECT_EQ(s.Dispose(At(1.0), /*late=*/false), FrameDisposition::kProcess);
    EXPECT_EQ(s.Dispose(At(1.0), /*late=*/true), policy == LateFramePolicy::kDrop
                                                     ? FrameDisposition::kDropLate
                                                     : FrameDisposition::kExtrapolate);
  }
}

TEST(FrameSchedulerTest, WithoutRecentGyroAFrameHasNoImu) {
  FrameSchedulerOptions o;
  o.imu_timeout_s = 1.0;
  Scheduler s{o};
  // No gyro at all, covered or late.
  EXPECT_EQ(s.Dispose(At(0.5), false), FrameDisposition::kNoImu);
  EXPECT_EQ(s.Dispose(At(0.5), true), FrameDisposition::kNoImu);
  FeedGyro(&s, 0.0, 1.0);
  // Exactly imu_timeout after the newest sample still counts; beyond, not.
  EXPECT_EQ(s.Dispose(At(2.0), true), FrameDisposition::kExtrapolate);
  EXPECT_EQ(s.Dispose(At(2.001), false), FrameDisposition::kNoImu);
  // No IMU wins over the late-frame policy.
  EXPECT_EQ(s.Dispose(At(2.001), true), FrameDisposition::kNoImu);
}

TEST(FrameSchedulerTest, ABurstBeyondTheQueueDropsTheOldestAndStaysBounded) {
  FrameSchedulerOptions o;
  o.frame_queue_size = 5;
  Scheduler s{o};
  int dropped = 0;
  for (int i = 0; i < 40; ++i) {
    const Admission a = s.Admit(i, At(0.033 * (i + 1)), At(0.0));
    ASSERT_NE(a, Admission::kOldStamp);
    dropped += a == Admission::kQueuedDroppedOldest;
    EXPECT_LE(s.queued(), 5u);
  }
  EXPECT_EQ(dropped, 35);
  EXPECT_EQ(s.queued(), 5u);
  EXPECT_EQ(s.Front()->frame, 35);  // the newest five are kept
  std::vector<int> out;
  while (auto r = s.ReleaseFront(false, std::nullopt, /*flush=*/true)) {
    EXPECT_TRUE(r->late);
    out.push_back(r->queued.frame);
  }
  EXPECT_EQ(out, (std::vector<int>{35, 36, 37, 38, 39}));
}

TEST(FrameSchedulerTest, AStampNotAfterThePreviousIsRefused) {
  Scheduler s{FrameSchedulerOptions{}};
  EXPECT_EQ(s.Admit(1, At(1.0), At(1.0)), Admission::kQueued);
  EXPECT_EQ(s.Admit(2, At(1.0), At(1.0)), Admission::kOldStamp);  // same stamp
  EXPECT_EQ(s.Admit(3, At(0.9), At(1.0)), Admission::kOldStamp);  // older than the queued
  const auto r = s.ReleaseFront(true, std::nullopt, false);
  ASSERT_TRUE(r.has_value());
  s.OnFrameDone(r->queued.stamp);
  // With none queued, the last processed frame's stamp is the bar.
  EXPECT_EQ(s.Admit(4, At(0.95), At(1.0)), Admission::kOldStamp);
  EXPECT_EQ(s.Admit(5, At(1.033), At(1.0)), Admission::kQueued);
  // A rebuilt pipeline starts a new sequence: an older stamp is taken.
  s.DropFront();
  s.ForgetLastFrame();
  EXPECT_EQ(s.Admit(6, At(0.5), At(1.0)), Admission::kQueued);
}

TEST(FrameSchedulerTest, ABackwardJumpOfEitherClockIsDetectedAndResetForgetsEverything) {
  FrameSchedulerOptions o;
  o.time_jump_s = 1.0;
  Scheduler s{o};
  FeedGyro(&s, 9.0, 10.0);
  s.Admit(1, At(10.0), At(10.0));
  s.OnFrameDone(s.ReleaseFront(true, std::nullopt, false)->queued.stamp);
  // Up to time_jump_s back is jitter (later refused as an old stamp), not a jump.
  EXPECT_FALSE(s.IsGyroTimeJump(At(9.0)));
  EXPECT_FALSE(s.IsFrameTimeJump(At(9.0)));
  EXPECT_TRUE(s.IsGyroTimeJump(At(8.99)));
  EXPECT_TRUE(s.IsFrameTimeJump(At(8.99)));
  s.Admit(2, At(10.033), At(10.0));
  s.Reset();
  EXPECT_EQ(s.queued(), 0u);
  EXPECT_TRUE(s.recent_gyro().empty());
  EXPECT_FALSE(s.have_gyro());
  EXPECT_FALSE(s.IsGyroTimeJump(At(0.0)));
  EXPECT_FALSE(s.IsFrameTimeJump(At(0.0)));
  // The new epoch starts from scratch.
  EXPECT_EQ(s.Admit(3, At(0.0), At(10.1)), Admission::kQueued);
  EXPECT_EQ(s.Dispose(At(0.0), false), FrameDisposition::kNoImu);
}

TEST(FrameSchedulerTest, OnlyGapsLongerThanTheWarningAreReported) {
  FrameSchedulerOptions o;
  o.imu_gap_warn_s = 0.05;
  Scheduler s{o};
  EXPECT_EQ(s.GyroGap(At(1.0)), 0.0);  // the first sample has no gap
  FeedGyro(&s, 0.0, 1.0);
  EXPECT_EQ(s.GyroGap(At(1.05)), 0.0);
  EXPECT_NEAR(s.GyroGap(At(1.3)), 0.3, 1e-12);
  EXPECT_EQ(s.GyroGap(At(0.5)), 0.0);  // older: not a gap
}

TEST(FrameSchedulerTest, TheReplayCopyIsBoundedByDurationAndCount) {
  Scheduler s{FrameSchedulerOptions{}};
  for (int i = 0; i <= 1000; ++i) s.OnGyroAccepted(Gyro(0.005 * i), FromSeconds(1.0), 100000);
  // 1 s at 200 Hz: the newest 201 samples (both ends inclusive).
  ASSERT_EQ(s.recent_gyro().size(), 201u);
  EXPECT_EQ(s.recent_gyro().back().stamp, At(5.0));
  EXPECT_EQ(s.recent_gyro().front().stamp, At(4.0));
  for (int i = 1001; i <= 1100; ++i) s.OnGyroAccepted(Gyro(0.005 * i), FromSeconds(10.0), 50);
  EXPECT_EQ(s.recent_gyro().size(), 50u);
  EXPECT_EQ(s.recent_gyro().back().stamp, At(5.5));
  // An out-of-order sample is kept, but the newest stamp stays.
  s.OnGyroAccepted(Gyro(5.4), FromSeconds(10.0), 50);
  EXPECT_EQ(s.last_gyro_stamp(), At(5.5));
}

TEST(FrameSchedulerTest, APipelinedHoldRunsOutAfterItsTimeOrAtTheEnd) {
  FrameSchedulerOptions o;
  o.pipeline_hold_s = 0.1;
  Scheduler s{o};
  EXPECT_FALSE(s.HoldRanOut(At(1.0), std::nullopt, false));
  EXPECT_FALSE(s.HoldRanOut(At(1.0), At(1.09), false));
  EXPECT_TRUE(s.HoldRanOut(At(1.0), At(1.1), false));
  EXPECT_TRUE(s.HoldRanOut(At(1.0), std::nullopt, /*flush=*/true));
}

}  // namespace
}  // namespace steadiface
