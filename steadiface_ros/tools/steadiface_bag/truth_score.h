#pragma once

#include <memory>
#include <string>

#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"

namespace steadiface_bag {

/// Scores a simulated bag's run against its ground truth with the
/// evaluation's scorecard (eval::Scorecard, the one steadiface_evaluate
/// uses): the truth file's settings rebuild the simulation; each
/// stabilized frame's warp (the pose, the layered mesh or the composite's
/// two poses) is added as the pipeline produces it, and the input
/// (identity) is scored on the same frames.
///
/// The scorer lives in a module (libsteadiface_truth_scorer.so), loaded with
/// dlopen only when a bag has a truth file to score: the simulator and the
/// evaluation libraries it needs link some 110 more shared libraries
/// (OpenCV's imgcodecs and theirs), which would slow every start of the
/// bag tool.
class TruthScorer {
 public:
  virtual ~TruthScorer() = default;

  /// Loads the module, reads `truth_path` (BAG.truth.csv), rebuilds its
  /// simulation and checks it against the file's rows. `options`: the run's
  /// pipeline options (the camera and output geometry the warps are in).
  static steadiface::Status Create(const std::string& truth_path,
                                   const steadiface::PipelineOptions& options,
                                   std::unique_ptr<TruthScorer>* out);

  /// A frame the pipeline just processed, stamped `stamp` (recorded clock).
  /// Frames the truth does not hold are counted and skipped.
  virtual void Add(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
                   const steadiface::Pipeline& pipeline) = 0;

  virtual steadiface::eval::Score Output() const = 0;
  virtual steadiface::eval::Score Input() const = 0;
  virtual const steadiface::eval::Scorecard& output_card() const = 0;
  virtual const steadiface::eval::Scorecard& input_card() const = 0;
  virtual int frames() const = 0;
  virtual int unmatched() const = 0;
  /// Wall time spent scoring (in Add) [s]: not the stabilizer's, so the
  /// report's throughput leaves it out.
  virtual double seconds() const = 0;
};

}  // namespace steadiface_bag

/// The module's entry point: a scorer for `truth_path`, or null with the
/// reason in *error.
extern "C" steadiface_bag::TruthScorer* steadiface_bag_create_truth_scorer(
    const std::string& truth_path, const steadiface::PipelineOptions& options,
    std::string* error);
