// E_p's wall where a face is held: the paper's protrusion term with a
// tolerance as stiff as the no-face one (α 0.002 of the width) against the
// stiff fitting term stops the solve short of both, and the face is knocked
// off its target for a frame where the margin is tight. The tolerance while
// a face is fitted (terms.protrusion_alpha_face) is softer; the protrusion
// search still checks the result exactly. docs/evaluation.md, "Where the
// dynamic crop's cost comes from", has the tables over seeds.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "score_util.h"
#include "sim_util.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;
using testing_util::ScoreRun;

/// `method` on `s` with E_p's face tolerance `alpha_face` (NaN: the
/// default) and the crop ratio `crop` (NaN: the default).
eval::Score RunWall(const sim::Simulator& s, eval::Method method,
                    double alpha_face, double crop) {
  return ScoreRun(s, method, [=](PipelineOptions* o) {
    if (std::isfinite(alpha_face))
      o->stabilizer.terms.protrusion_alpha_face = alpha_face;
    if (std::isfinite(crop)) o->warp.output.crop_ratio = crop;
  });
}

// walk (seed 1) with 0.85 of the width kept: the stiff wall knocks the face
// off its target where the margin runs out. (The event was found on vlog:
// one frame held 12 px off, 22 solver iterations, E_p at 0. Since the
// pose-invariant centre takes back part of the nod, vlog's path no longer
// meets the wall; walk's does.)
TEST(ProtrusionWallTest, AFaceHeldAtATightMarginIsNotKnockedOffItsTarget) {
  const auto s = MakeSimulator("walk");
  const double stiff_alpha = StabilizerOptions().terms.protrusion_alpha;
  const eval::Score stiff =
      RunWall(*s, eval::Method::kSteadiface, stiff_alpha, 0.075);
  const eval::Score ours = RunWall(*s, eval::Method::kSteadiface, NAN, 0.075);
  std::cout << "[ walk, 0.85 kept ] head px: stiff wall "
            << stiff.head_jitter_px << " (largest step "
            << stiff.head_max_step_px << "), face's wall "
            << ours.head_jitter_px << " (" << ours.head_max_step_px << ")\n";
  // Measured: 3.74 px, largest step 17.10 px -> 1.68 px, 5.58 px (on vlog
  // before the nod's share: 1.87 px, 12.06 px -> 1.18 px, 4.89 px).
  EXPECT_LT(ours.head_jitter_px, 0.8 * stiff.head_jitter_px);
  EXPECT_LT(ours.head_max_step_px, 0.6 * stiff.head_max_step_px);
  EXPECT_EQ(ours.undefined_fraction, 0.0);
}

// run (seed 1), the default crop: the margin runs out on the strides; the
// softer wall takes the largest step of the held head down, and leaves
// gyro-only, which fits no face, exactly as it was.
TEST(ProtrusionWallTest, TheNoFaceWallIsUnchangedAndTheHeldHeadStepsLess) {
  const auto s = MakeSimulator("run");
  const double stiff_alpha = StabilizerOptions().terms.protrusion_alpha;
  const eval::Score stiff =
      RunWall(*s, eval::Method::kSteadiface, stiff_alpha, NAN);
  const eval::Score ours = RunWall(*s, eval::Method::kSteadiface, NAN, NAN);
  const eval::Score gyro_stiff =
      RunWall(*s, eval::Method::kGyroOnly, stiff_alpha, NAN);
  const eval::Score gyro = RunWall(*s, eval::Method::kGyroOnly, NAN, NAN);
  std::cout << "[ run ] head px: stiff wall " << stiff.head_jitter_px
            << " (largest step " << stiff.head_max_step_px << "), face's wall "
            << ours.head_jitter_px << " (" << ours.head_max_step_px
            << "); gyro-only " << gyro.head_jitter_px << "\n";
  // Measured (seed 1): 6.64 px, largest step 34.23 px -> 5.85 px, 22.55 px.
  EXPECT_LT(ours.head_max_step_px, 0.8 * stiff.head_max_step_px);
  EXPECT_LT(ours.head_jitter_px, stiff.head_jitter_px);
  EXPECT_EQ(ours.undefined_fraction, 0.0);
  EXPECT_EQ(gyro.head_jitter_px, gyro_stiff.head_jitter_px);
  EXPECT_EQ(gyro.background_jitter_px, gyro_stiff.background_jitter_px);
}

}  // namespace
}  // namespace steadiface
