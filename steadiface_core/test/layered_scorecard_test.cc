// The layered warp (issue 15) on simulated sequences with ground truth:
// the scorecard bars against global steadiface and gyro-only, the mesh's
// distortion bounds, and the return to one global warp when the face is
// lost. docs/evaluation.md ("Layered warp") has the full-length table.
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline.h"
#include "steadiface_core/sim/simulator.h"
#include "sim_util.h"

namespace steadiface {
namespace {

std::unique_ptr<sim::Simulator> Make(const std::string& preset,
                                     std::function<void(sim::SimulatorOptions*)> tweak = {}) {
  return testing_util::MakeSimulator(preset, tweak);
}

eval::Score Score(const sim::Simulator& s, eval::Method m) {
  const PipelineOptions o = eval::OptionsFor(s, m);
  std::unique_ptr<eval::Scorecard> card;
  EXPECT_TRUE(eval::MakeScorecard(s, o, &card).ok());
  const Status st = eval::RunMethod(s, m, o, false, card.get(), nullptr);
  EXPECT_TRUE(st.ok()) << st.message();
  return card->Compute();
}

class LayeredScorecardTest : public ::testing::TestWithParam<std::string> {};

// The bars, per preset (3 s each): the head as steady as global
// steadiface's (<= 1.3x), the visible background near gyro-only's
// (<= 1.5x), no fold-over, every cell's singular-value ratio >= 0.5, no
// undefined pixels, and the band's jitter below the background jitter that
// global steadiface shows.
TEST_P(LayeredScorecardTest, HoldsTheHeadAndTheBackground) {
  const auto s = Make(GetParam());
  const eval::Score gyro = Score(*s, eval::Method::kGyroOnly);
  const eval::Score global = Score(*s, eval::Method::kSteadiface);
  const eval::Score layered = Score(*s, eval::Method::kSteadifaceLayered);
  std::cout << "[ " << GetParam() << " ] head px: global "
            << global.head_jitter_px << ", layered " << layered.head_jitter_px
            << "; visible background px: gyro-only "
            << gyro.visible_background_jitter_px << ", global "
            << global.visible_background_jitter_px << ", layered "
            << layered.visible_background_jitter_px << "; cells: worst "
            << layered.min_cell_ratio << ", p01 " << layered.p01_cell_ratio
            << ", folded " << layered.folded_cells << "; line deviation "
            << layered.line_deviation_px << " px (global "
            << global.line_deviation_px << "); band jitter "
            << layered.band_jitter_px << " px\n";
  EXPECT_LE(layered.head_jitter_px, 1.3 * global.head_jitter_px + 0.02);
  EXPECT_LE(layered.visible_background_jitter_px,
            1.5 * gyro.visible_background_jitter_px + 0.02);
  EXPECT_EQ(layered.folded_cells, 0);
  EXPECT_GE(layered.min_cell_ratio, 0.5);
  EXPECT_EQ(layered.undefined_fraction, 0.0);
  if (std::isfinite(layered.band_jitter_px)) {
    EXPECT_LT(layered.band_jitter_px, global.visible_background_jitter_px);
  }
  // A global pose warp keeps straight lines straight (up to the mesh's
  // bilinear cells); the band bends them, by a bounded amount.
  EXPECT_LT(global.line_deviation_px, 0.3);
  EXPECT_LT(layered.line_deviation_px, 12.0);
}

INSTANTIATE_TEST_SUITE_P(Presets, LayeredScorecardTest,
                         ::testing::Values("walk", "vlog", "pan", "run",
                                           "still"));

// When the face is lost (it leaves the frame sideways for about a second)
// the blend ramps to 0, the output becomes one global warp (exactly the
// background layer's mesh), and the blend comes back when the face does,
// never stepping by more than dt / ramp.
TEST(LayeredWarpTest, FaceLossReturnsToOneGlobalWarpWithoutAJump) {
  const auto s = Make("walk", [](sim::SimulatorOptions* o) {
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
      ASSERT_EQ(p->warper().mesh().source, p->warper().background_mesh());
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
