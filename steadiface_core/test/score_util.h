#pragma once
// A method run over a simulator and scored, as the scenario tests do.

#include <functional>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace testing_util {

/// `method` on `s` with the options eval::OptionsFor gives, changed by
/// `tweak`, scored; `frames` (optional) gets the stabilizer's record. A
/// failure is a test failure and an empty score.
inline eval::Score ScoreRun(const sim::Simulator& s, eval::Method method,
                            const std::function<void(PipelineOptions*)>& tweak = {},
                            std::vector<StabilizerFrame>* frames = nullptr) {
  PipelineOptions po = eval::OptionsFor(s, method);
  if (tweak) tweak(&po);
  std::unique_ptr<eval::Scorecard> card;
  Status st = eval::MakeScorecard(s, po, &card);
  eval::RunMethodOptions run;
  run.frames = frames;
  if (st.ok()) st = eval::RunMethod(s, method, po, card.get(), run);
  EXPECT_TRUE(st.ok()) << st.message();
  return st.ok() ? card->Compute() : eval::Score();
}

}  // namespace testing_util
}  // namespace steadiface
