// The truth scorer's module (libsteadiface_truth_scorer.so): TruthScorer's
// implementation, linked against the simulator and the evaluation libraries.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include "steadiface_bag/truth_score.h"

#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/sim/simulator.h"
#include "steadiface_core/sim/truth_file.h"

namespace steadiface_bag {
namespace {

// The rebuilt simulation must reproduce the file's truth (else the photos
// or the simulator changed since the bag was made).
steadiface::Status CheckRows(const steadiface::sim::Simulator& sim,
                             const std::vector<steadiface::sim::TruthRow>& rows) {
  for (const auto& row : rows) {
    if (row.frame < 0 || row.frame >= sim.num_frames()) {
      return steadiface::Status::Error("truth frame " + std::to_string(row.frame) +
                                       " is not in the rebuilt simulation");
    }
    const steadiface::sim::SimTruth t = sim.Truth(row.frame);
    if (t.head_in_view != row.truth.head_in_view ||
        (t.head_in_view && (t.head_px - row.truth.head_px).norm() > 1e-6)) {
      return steadiface::Status::Error(
          "the rebuilt simulation's head differs from the truth file's at frame " +
          std::to_string(row.frame));
    }
  }
  return steadiface::Status::Ok();
}

class TruthScorerImpl : public TruthScorer {
 public:
  static steadiface::Status Create(const std::string& truth_path,
                                   const steadiface::PipelineOptions& options,
                                   std::unique_ptr<TruthScorerImpl>* out);
  void Add(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
           const steadiface::Pipeline& pipeline) override;
  steadiface::eval::Score Output() const override { return output_->Compute(); }
  steadiface::eval::Score Input() const override { return input_->Compute(); }
  const steadiface::eval::Scorecard& output_card() const override { return *output_; }
  const steadiface::eval::Scorecard& input_card() const override { return *input_; }
  int frames() const override { return frames_; }
  int unmatched() const override { return unmatched_; }
  double seconds() const override { return seconds_; }

 private:
  void AddTimed(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
                const steadiface::Pipeline& pipeline);

  std::unique_ptr<steadiface::sim::Simulator> sim_;
  std::unique_ptr<steadiface::eval::Scorecard> output_, input_;
  std::map<int64_t, int> frame_by_ms_;
  int frames_ = 0, unmatched_ = 0;
  double seconds_ = 0.0;
};

}  // namespace

steadiface::Status TruthScorerImpl::Create(const std::string& truth_path,
                                           const steadiface::PipelineOptions& options,
                                           std::unique_ptr<TruthScorerImpl>* out) {
  steadiface::sim::SimulationSettings settings;
  bool has_settings = false;
  std::vector<steadiface::sim::TruthRow> rows;
  steadiface::Status s = steadiface::sim::ReadTruthFile(truth_path, &settings, &has_settings, &rows);
  if (!s.ok()) return s;
  if (!has_settings) {
    return steadiface::Status::Error("'" + truth_path +
                                     "' has no simulation settings (made by an older "
                                     "steadiface_simulate): no ground-truth score");
  }
  std::unique_ptr<TruthScorerImpl> t(new TruthScorerImpl);
  steadiface::sim::SimulatorOptions so;
  s = steadiface::sim::MakeSimulatorOptions(settings, &so);
  if (s.ok()) s = steadiface::sim::Simulator::Create(so, &t->sim_);
  if (s.ok()) s = CheckRows(*t->sim_, rows);
  if (s.ok()) s = steadiface::eval::MakeScorecard(*t->sim_, options, &t->output_);
  if (s.ok()) s = steadiface::eval::MakeScorecard(*t->sim_, options, &t->input_);
  if (!s.ok()) return s;
  t->frame_by_ms_ = steadiface::sim::FramesByStampMs(rows);
  *out = std::move(t);
  return steadiface::Status::Ok();
}

void TruthScorerImpl::Add(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
                      const steadiface::Pipeline& pipeline) {
  const auto start = std::chrono::steady_clock::now();
  AddTimed(stamp, frame, pipeline);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void TruthScorerImpl::AddTimed(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
                           const steadiface::Pipeline& pipeline) {
  const auto it = frame_by_ms_.find(std::llround(steadiface::ToSeconds(stamp) * 1000.0));
  if (it == frame_by_ms_.end()) {
    ++unmatched_;
    return;
  }
  output_->Add(it->second, steadiface::eval::MakeFrameWarp(frame, pipeline, false));
  input_->Add(it->second, steadiface::eval::FrameWarp());
  ++frames_;
}

}  // namespace steadiface_bag

steadiface_bag::TruthScorer* steadiface_bag_create_truth_scorer(
    const std::string& truth_path, const steadiface::PipelineOptions& options,
    std::string* error) {
  std::unique_ptr<steadiface_bag::TruthScorerImpl> t;
  const steadiface::Status s = steadiface_bag::TruthScorerImpl::Create(truth_path, options, &t);
  if (!s.ok()) {
    *error = s.message();
    return nullptr;
  }
  return t.release();
}
