// The layered warp on simulated sequences with ground truth: the scorecard
// bars against gyro-only (the background layer's own pose), the mesh's
// distortion bounds, hand-overs without jumps, and the return to one global
// warp when the face is lost. docs/evaluation.md has the table over seeds.
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "sim_util.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;

eval::Score Score(const sim::Simulator& s, eval::Method m) {
  PipelineOptions o = eval::OptionsFor(s, m);
  // The flat photo's landmarks do not swing as it turns: the landmarks'
  // own centre (the pose-invariant centre would correct a swing that is
  // not there).
  o.stabilizer.dynamic.pose_pivot_depth = 0.0;
  std::unique_ptr<eval::Scorecard> card;
  EXPECT_TRUE(eval::MakeScorecard(s, o, &card).ok());
  const Status st = eval::RunMethod(s, m, o, card.get());
  EXPECT_TRUE(st.ok()) << st.message();
  return card->Compute();
}

// One preset's expectations for the layered warp against gyro-only's
// (seed 1, 3 s; run and shake 9.8 s). head_ratio: the head jitter bar, layered /
// gyro-only. Where the bar of the background-first design cannot be met,
// the measured ratio plus a margin guards against regressions, and the
// reason is given (docs/evaluation.md, "The background layer never moved").
struct LayeredCase {
  std::string preset;
  double head_ratio;  ///< layered head jitter <= this x gyro-only's
  double line_px;     ///< worst straight-line deviation in the band [px]
  /// The output head's largest second difference per frame <= this x
  /// gyro-only's + 1 px (no jump beyond the face's own motion); 0 = not
  /// checked (occlusion: the face's loss and return jump in both modes).
  double jump_ratio = 1.5;
};

void PrintTo(const LayeredCase& c, std::ostream* os) { *os << c.preset; }

class LayeredScorecardTest : public ::testing::TestWithParam<LayeredCase> {};

// The bars: visible background <= 1.2x gyro-only's on every preset (the
// face never moves the background); the head per preset as above; no
// fold-over, every cell's singular-value ratio >= 0.5, no undefined pixels;
// straight lines bend only in the band, within a bound; and the hand-overs
// never jump: the output head moves about as abruptly as the face itself
// in the steady scene, not more.
TEST_P(LayeredScorecardTest, NeverMovesTheBackgroundAndHoldsTheHead) {
  const LayeredCase& c = GetParam();
  const auto s = MakeSimulator(c.preset, [&](sim::SimulatorOptions* o) {
    // As steadiface_evaluate: a preset replaying the recorded trace runs its
    // whole length.
    if (c.preset == "shake" || c.preset == "run") o->duration_s = 9.8;
    // The mesh's bars were measured with the flat face (and the landmarks'
    // centre, Score()); the relief head's own figures (its turning moves
    // the landmarks) are in docs/evaluation.md, "A head that turns like a
    // head".
    o->head_model = "flat";
  });
  const eval::Score gyro = Score(*s, eval::Method::kGyroOnly);
  const eval::Score global = Score(*s, eval::Method::kSteadiface);
  const eval::Score layered = Score(*s, eval::Method::kSteadifaceLayered);
  std::cout << "[ " << c.preset << " ] head px: gyro-only " << gyro.head_jitter_px << ", global "
            << global.head_jitter_px << ", layered " << layered.head_jitter_px
            << "; visible background px: gyro-only " << gyro.visible_background_jitter_px
            << ", global " << global.visible_background_jitter_px << ", layered "
            << layered.visible_background_jitter_px << "; cells: worst " << layered.min_cell_ratio
            << ", p01 " << layered.p01_cell_ratio << ", folded " << layered.folded_cells
            << "; lines: worst " << layered.line_deviation_px << " px, p99 "
            << layered.line_deviation_p99_px << " px; largest steps (2nd diff): blend "
            << layered.blend_max_step_px << " (" << layered.blend_max_accel_px
            << ") px, head target " << layered.head_target_max_step_px << " ("
            << layered.head_target_max_accel_px << ") px, head " << layered.head_max_step_px << " ("
            << layered.head_max_accel_px << ") px (gyro-only " << gyro.head_max_step_px << " ("
            << gyro.head_max_accel_px << "))\n";
  EXPECT_LE(layered.visible_background_jitter_px, 1.2 * gyro.visible_background_jitter_px);
  EXPECT_LE(layered.head_jitter_px, c.head_ratio * gyro.head_jitter_px);
  EXPECT_EQ(layered.folded_cells, 0);
  EXPECT_GE(layered.min_cell_ratio, 0.5 - 1e-4);  // the pull's bisection tolerance
  EXPECT_EQ(layered.undefined_fraction, 0.0);
  // One pose keeps lines straight, up to the rolling shutter under the
  // shake preset's 3x running trace.
  EXPECT_LT(global.line_deviation_px, c.preset == "shake" ? 1.0 : 0.3);
  EXPECT_LE(layered.line_deviation_px, c.line_px);
  // No jumps: the head as the output shows it moves about as abruptly
  // (largest second difference per frame) as the face itself does in the
  // steady scene (gyro-only's output), not more; a hand-over that jumped
  // would show there. Measured ratios 0.5-1.35x (docs/evaluation.md).
  if (c.jump_ratio > 0.0) {
    EXPECT_LE(layered.head_max_accel_px, c.jump_ratio * gyro.head_max_accel_px + 1.0);
  }
}

// Head bars met (<= 0.5x gyro-only): walk, vlog, pan, run, two_faces
// (0.14-0.36x over seeds 1-3). Still camera: the head is not chased
// (layered = gyro-only's 1.0x). Not met, guarded at the measured ratio +
// ~0.1: occlusion (0.47-0.65x; global 0.51-0.66x: the tracker accepts
// landmarks dragged by the hand as it enters), turn_away (0.58-0.83x: no
// landmarks while the face is turned away), drift (0.76-0.84x: the head
// follows its own slow drift in the steady scene by design; no causal
// policy tried within the reach gets below 0.66x), walk_across
// (0.65-0.68x: the subject's gait against the scene exceeds what the band
// absorbs around a face this small for the mesh), shake (0.80-0.82x: even
// the non-causal optimum within the reach is 0.72-0.74x; global's 0.53x
// moves the background with the face). docs/evaluation.md, "The face's own
// cell".
INSTANTIATE_TEST_SUITE_P(
    Presets, LayeredScorecardTest,
    ::testing::Values(LayeredCase{"walk", 0.5, 3.0}, LayeredCase{"vlog", 0.5, 3.0},
                      LayeredCase{"pan", 0.5, 3.0}, LayeredCase{"run", 0.5, 5.0},
                      LayeredCase{"two_faces", 0.5, 3.0}, LayeredCase{"still", 1.01, 0.3},
                      LayeredCase{"occlusion", 0.6, 3.0, 0.0}, LayeredCase{"turn_away", 0.7, 3.0},
                      LayeredCase{"drift", 0.95, 3.0}, LayeredCase{"walk_across", 0.75, 3.0},
                      LayeredCase{"shake", 0.9, 25.0}),
    [](const ::testing::TestParamInfo<LayeredCase>& info) { return info.param.preset; });

// The pipeline keeps the stabilizer options as requested and derives the
// layered ones from the warp each time: the reach follows a reconfigured
// band (width x cap), a stabilizer update keeps it, and global mode drops
// the background layer that only layered mode asked for.
TEST(LayeredWarpTest, TheReachFollowsTheBandWhenReconfigured) {
  const auto s = MakeSimulator("walk");
  const PipelineOptions o = eval::OptionsFor(*s, eval::Method::kSteadifaceLayered);
  ASSERT_EQ(o.stabilizer.subject_reach, 0.0);
  ASSERT_FALSE(o.stabilizer.background_layer);
  std::unique_ptr<Pipeline> p;
  ASSERT_TRUE(Pipeline::Create(s->intrinsics(), o, &p).ok());
  const LayerBlendOptions& b = o.warp.layered.blend;
  EXPECT_DOUBLE_EQ(p->stabilizer().options().subject_reach, b.band_width * b.max_offset);
  EXPECT_TRUE(p->stabilizer().options().background_layer);
  EXPECT_EQ(p->options().stabilizer.subject_reach, 0.0);  // as requested
  LayeredWarpOptions wider = o.warp.layered;
  wider.blend.band_width = 0.5;
  ASSERT_TRUE(p->UpdateLayering(WarpMode::kLayered, wider).ok());
  EXPECT_DOUBLE_EQ(p->stabilizer().options().subject_reach, 0.5 * b.max_offset);
  ASSERT_TRUE(p->UpdateStabilizerOptions(p->options().stabilizer).ok());
  EXPECT_DOUBLE_EQ(p->stabilizer().options().subject_reach, 0.5 * b.max_offset);
  ASSERT_TRUE(p->UpdateLayering(WarpMode::kGlobal, wider).ok());
  EXPECT_FALSE(p->stabilizer().options().background_layer);
  EXPECT_EQ(p->stabilizer().options().subject_reach, 0.0);
}

// When the face is lost (it leaves the frame sideways for about a second)
// the blend ramps to 0, the output becomes one global warp (exactly the
// background layer's mesh), and the blend comes back when the face does,
// never stepping by more than dt / ramp.
TEST(LayeredWarpTest, FaceLossReturnsToOneGlobalWarpWithoutAJump) {
  const auto s = MakeSimulator("walk", [](sim::SimulatorOptions* o) {
    o->duration_s = 4.0;
    o->face_out_start_s = 0.8;
    o->face_out_end_s = 2.0;
  });
  PipelineOptions o = eval::OptionsFor(*s, eval::Method::kSteadifaceLayered);
  std::unique_ptr<Pipeline> p;
  ASSERT_TRUE(Pipeline::Create(s->intrinsics(), o, &p).ok());
  size_t g = 0;
  double max_step = 0.0, min_blend = 1.0, last_blend = 0.0;
  int frames_global = 0;
  for (int i = 0; i < s->num_frames(); ++i) {
    cv::Mat frame;
    sim::SimTruth truth;
    ASSERT_TRUE(s->Render(i, &frame, &truth).ok());
    eval::FeedGyroForFrame(*s, truth.stamp, o.imu.imu_time_offset_s, p.get(),
                           &g);
    PipelineFrame f;
    ASSERT_TRUE(p->ProcessFrame(frame, truth.stamp, nullptr, 0.0, &f).ok());
    ASSERT_TRUE(f.layered.active);
    max_step = std::max(max_step, f.layered.region.blend_step);
    min_blend = std::min(min_blend, f.layered.region.blend);
    last_blend = f.layered.region.blend;
    EXPECT_EQ(f.layered.blend.folded_cells, 0) << "frame " << i;
    if (!f.layered.blend.layered) {
      // Blend 0: the mesh is exactly the background layer's.
      ++frames_global;
      const auto& mesh = p->warper().mesh().source;
      const auto& background = p->warper().background_mesh();
      ASSERT_EQ(mesh.size(), background.size());
      double worst = 0.0;
      for (size_t k = 0; k < mesh.size(); ++k) {
        worst = std::max(worst, static_cast<double>((mesh[k] - background[k]).norm()));
      }
      ASSERT_EQ(worst, 0.0) << "frame " << i;  // (gtest cannot print Eigen vectors)
    }
  }
  const double ramp = o.warp.layered.region.ramp_s;
  std::cout << "[ face out ] blend: min " << min_blend << ", largest step "
            << max_step << " (bound " << 1.0 / (s->options().fps * ramp)
            << "), frames as one global warp " << frames_global << ", last "
            << last_blend << "\n";
  EXPECT_LE(max_step, 1.0 / (s->options().fps * ramp) * (1 + 1e-6));
  EXPECT_EQ(min_blend, 0.0);  // the loss was seen and the warp went global
  EXPECT_GT(frames_global, 5);
  EXPECT_GT(last_blend, 0.95);  // and the face came back
}

}  // namespace
}  // namespace steadiface
