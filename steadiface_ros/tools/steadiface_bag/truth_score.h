#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "steadiface_core/common/status.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface_bag {

/// Scores a simulated bag's run against its ground truth with the
/// evaluation's scorecard (eval::Scorecard, the one steadiface_evaluate
/// uses): the truth file's settings rebuild the simulation; each
/// stabilized frame's warp (the pose, or the layered mesh) is added as the
/// pipeline produces it, and the input (identity) is scored on the same
/// frames.
class TruthScorer {
 public:
  /// Reads `truth_path` (BAG.truth.csv), rebuilds its simulation and checks
  /// it against the file's rows. `options`: the run's pipeline options (the
  /// camera and output geometry the warps are in).
  static steadiface::Status Create(const std::string& truth_path,
                                   const steadiface::PipelineOptions& options,
                                   std::unique_ptr<TruthScorer>* out);

  /// A frame the pipeline just processed, stamped `stamp` (recorded clock).
  /// Frames the truth does not hold are counted and skipped.
  void Add(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
           const steadiface::Pipeline& pipeline);

  steadiface::eval::Score Output() const { return output_->Compute(); }
  steadiface::eval::Score Input() const { return input_->Compute(); }
  const steadiface::eval::Scorecard& output_card() const { return *output_; }
  const steadiface::eval::Scorecard& input_card() const { return *input_; }
  int frames() const { return frames_; }
  int unmatched() const { return unmatched_; }
  /// Wall time spent scoring (in Add) [s]: not the stabilizer's, so the
  /// report's throughput leaves it out.
  double seconds() const { return seconds_; }

 private:
  TruthScorer() = default;
  void AddTimed(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
                const steadiface::Pipeline& pipeline);

  std::unique_ptr<steadiface::sim::Simulator> sim_;
  std::unique_ptr<steadiface::eval::Scorecard> output_, input_;
  std::map<int64_t, int> frame_by_ms_;
  int frames_ = 0, unmatched_ = 0;
  double seconds_ = 0.0;
};

}  // namespace steadiface_bag
