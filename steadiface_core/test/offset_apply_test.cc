// gyro_video_check/apply_offset (and the deferred render) through the whole pipeline, against
// simulator ground truth: the node is configured with a clock offset that
// is wrong by a known amount, and the applied correction must converge to
// that amount and give back the background steadiness of the right
// configuration; with the right configuration it must stay near zero and
// cost nothing.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

struct ApplyRun {
  std::vector<double> t, applied;  // per frame [s]
  double late_bg_jitter_px = NAN;  // background jitter, frames after late_s
  double final_applied_s = NAN;
  bool rotation_contradicted = false;  // the check blamed the rotation
};

// Gyro-only stabilization of `preset` (rendered, so the check sees the
// video; the face is in view and not excluded: no face tracker), with
// imu/time_offset misconfigured by `offset_error_s`.
ApplyRun RunApply(const std::string& preset, double seconds,
                  double offset_error_s, bool apply, double late_s,
                  const Eigen::Quaterniond& configured_R_cam_imu =
                      Eigen::Quaterniond::Identity()) {
  sim::SimulatorOptions so;
  EXPECT_TRUE(sim::ApplyPreset(preset, &so).ok());
  so.data_dir = STEADIFACE_TEST_DATA_DIR;
  so.duration_s = seconds;
  so.width = 480;
  so.height = 270;
  std::unique_ptr<sim::Simulator> sim;
  EXPECT_TRUE(sim::Simulator::Create(so, &sim).ok());
  PipelineOptions po = eval::OptionsFor(*sim, eval::Method::kGyroOnly);
  po.imu.imu_time_offset_s += offset_error_s;
  po.gyro_video_check.apply_offset = apply;  // default: on
  po.imu.R_cam_imu = configured_R_cam_imu;
  std::unique_ptr<Pipeline> p;
  EXPECT_TRUE(Pipeline::Create(sim->intrinsics(), po, &p).ok());
  std::unique_ptr<eval::Scorecard> card;
  EXPECT_TRUE(eval::MakeScorecard(*sim, po, &card).ok());
  ApplyRun run;
  size_t g = 0;
  cv::Mat frame;
  sim::SimTruth truth;
  for (int i = 0; i < sim->num_frames(); ++i) {
    const Time stamp = sim->Truth(i).stamp;
    eval::FeedGyroForFrame(*sim, stamp, po.imu.imu_time_offset_s, p.get(), &g);
    EXPECT_TRUE(sim->Render(i, &frame, &truth).ok());
    PipelineFrame out;
    EXPECT_TRUE(p->ProcessFrame(frame, stamp, nullptr, 0.0, &out).ok());
    run.t.push_back(ToSeconds(stamp - sim->Truth(0).stamp));
    run.applied.push_back(out.imu_offset_applied_s);
    run.rotation_contradicted |= out.gyro_video_check.rotation_contradicts;
    if (run.t.back() >= late_s) {
      eval::FrameWarp w;
      w.kind = eval::FrameWarp::Kind::kPose;
      w.R_v = out.stabilizer.R_v;
      w.t = out.stabilizer.t;
      w.rows = out.stabilizer.rows;
      card->Add(i, w);
    }
  }
  run.late_bg_jitter_px = card->Compute().visible_background_jitter_px;
  run.final_applied_s = run.applied.back();
  std::cout << "  " << preset << ", offset error " << offset_error_s * 1e3
            << " ms, apply " << apply << ": applied";
  for (size_t i = 0; i < run.t.size(); i += 30) {
    std::cout << " " << std::round(run.applied[i] * 1e4) / 10;
  }
  std::cout << " ms; background jitter after " << late_s
            << " s: " << run.late_bg_jitter_px << " px\n";
  return run;
}

// The applied correction undoes a 30 ms error (the timeline then reads the
// gyro as the right configuration would), and the background is as steady
// as with the right configuration.
TEST(OffsetApplyTest, AThirtyMillisecondErrorIsUndone) {
  const ApplyRun right = RunApply("walk", 12.0, 0.0, false, 9.0);
  const ApplyRun wrong = RunApply("walk", 12.0, -0.030, false, 9.0);
  const ApplyRun applied = RunApply("walk", 12.0, -0.030, true, 9.0);
  EXPECT_NEAR(applied.final_applied_s, 0.030, 0.003);
  // Rate-limited: never faster than apply_rate (5 ms/s) allows.
  for (size_t i = 1; i < applied.t.size(); ++i) {
    EXPECT_LE(std::abs(applied.applied[i] - applied.applied[i - 1]),
              0.005 * (applied.t[i] - applied.t[i - 1]) + 1e-9);
  }
  EXPECT_GT(wrong.late_bg_jitter_px, 2.0 * right.late_bg_jitter_px);
  EXPECT_LT(applied.late_bg_jitter_px, 1.15 * right.late_bg_jitter_px);
}

// With the right offset the correction stays small and costs nothing.
TEST(OffsetApplyTest, TheRightOffsetStaysPut) {
  const ApplyRun off = RunApply("walk", 12.0, 0.0, false, 9.0);
  const ApplyRun on = RunApply("walk", 12.0, 0.0, true, 9.0);
  for (double a : on.applied) EXPECT_LT(std::abs(a), 0.003);
  EXPECT_LT(on.late_bg_jitter_px, 1.1 * off.late_bg_jitter_px);
}

// A wrong IMU rotation is the check's first complaint: no offset is applied
// while the rotation contradicts the video (an offset fitted under a wrong
// rotation means nothing).
TEST(OffsetApplyTest, NothingIsAppliedUnderAWrongRotation) {
  const Eigen::Quaterniond permuted =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  const ApplyRun run = RunApply("walk", 6.0, -0.030, true, 3.0, permuted);
  EXPECT_TRUE(run.rotation_contradicted);
  for (double a : run.applied) EXPECT_EQ(a, 0.0);
}

}  // namespace
}  // namespace steadiface

namespace steadiface {
namespace {

// The two-stage pipeline: ProcessFrameDeferred + RenderDeferred (on another
// thread, while the next frame is processed) gives ProcessFrame's output
// bit for bit, in global and layered mode.
TEST(DeferredRenderTest, MatchesTheOneStagePipelineBitForBit) {
  sim::SimulatorOptions so;
  ASSERT_TRUE(sim::ApplyPreset("vlog", &so).ok());
  so.data_dir = STEADIFACE_TEST_DATA_DIR;
  so.duration_s = 1.0;
  so.width = 480;
  so.height = 270;
  std::unique_ptr<sim::Simulator> sim;
  ASSERT_TRUE(sim::Simulator::Create(so, &sim).ok());
  for (WarpMode mode : {WarpMode::kGlobal, WarpMode::kLayered}) {
    PipelineOptions po = eval::OptionsFor(*sim, eval::Method::kSteadiface);
    po.warp.mode = mode;
    po.render_output = true;
    std::unique_ptr<Pipeline> one, two;
    ASSERT_TRUE(Pipeline::Create(sim->intrinsics(), po, &one).ok());
    ASSERT_TRUE(Pipeline::Create(sim->intrinsics(), po, &two).ok());
    size_t g1 = 0, g2 = 0;
    std::thread worker;
    PipelineFrame held;
    double held_processing_ms = 0.0;
    cv::Mat held_image;
    std::vector<cv::Mat> expected, got;
    for (int i = 0; i < sim->num_frames(); ++i) {
      const Time stamp = sim->Truth(i).stamp;
      eval::FeedGyroForFrame(*sim, stamp, po.imu.imu_time_offset_s, one.get(), &g1);
      eval::FeedGyroForFrame(*sim, stamp, po.imu.imu_time_offset_s, two.get(), &g2);
      cv::Mat frame;
      sim::SimTruth truth;
      ASSERT_TRUE(sim->Render(i, &frame, &truth).ok());
      PipelineFrame a, b;
      ASSERT_TRUE(one->ProcessFrame(frame, stamp, nullptr, 0.0, &a).ok());
      expected.push_back(a.output);
      ASSERT_TRUE(two->ProcessFrameDeferred(frame, stamp, nullptr, 0.0, &b).ok());
      EXPECT_TRUE(b.output.empty());
      if (worker.joinable()) {
        worker.join();
        got.push_back(held.output);
      }
      // total_ms counts the render too once it has run (the published
      // StabilizerState's processing time).
      EXPECT_EQ(b.timings.remap_ms, 0.0);
      held_processing_ms = b.timings.total_ms;
      held = std::move(b);
      held_image = frame;
      worker = std::thread([&held, &held_image] { Pipeline::RenderDeferred(held_image, &held); });
    }
    worker.join();
    got.push_back(held.output);
    EXPECT_GT(held.timings.remap_ms, 0.0);
    EXPECT_EQ(held.timings.total_ms, held_processing_ms + held.timings.remap_ms);
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].size(), expected[i].size());
      EXPECT_EQ(cv::norm(got[i], expected[i], cv::NORM_INF), 0.0)
          << WarpModeName(mode) << " frame " << i;
    }
  }
}

}  // namespace
}  // namespace steadiface
