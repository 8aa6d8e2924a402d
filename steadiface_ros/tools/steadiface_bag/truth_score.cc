#include "steadiface_bag/truth_score.h"

#include <chrono>
#include <cmath>
#include <vector>

#include "steadiface_core/eval/run_methods.h"
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

}  // namespace

steadiface::Status TruthScorer::Create(const std::string& truth_path,
                                       const steadiface::PipelineOptions& options,
                                       std::unique_ptr<TruthScorer>* out) {
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
  std::unique_ptr<TruthScorer> t(new TruthScorer);
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

void TruthScorer::Add(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
                      const steadiface::Pipeline& pipeline) {
  const auto start = std::chrono::steady_clock::now();
  AddTimed(stamp, frame, pipeline);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void TruthScorer::AddTimed(steadiface::Time stamp, const steadiface::PipelineFrame& frame,
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
