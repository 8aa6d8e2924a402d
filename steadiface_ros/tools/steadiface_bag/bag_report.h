#pragma once

#include <string>

#include "steadiface_bag/bag_writer.h"
#include "steadiface_bag/truth_score.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace steadiface_bag {

/// What the report needs to know of the run besides the sink's records.
struct ReportInputs {
  std::string in;     ///< input bag path
  std::string truth;  ///< simulator ground truth CSV ("" = none)
  /// The run scored against `truth` (null = no ground-truth block).
  const TruthScorer* scorer = nullptr;
  std::string
      plot_dir;  ///< trajectories for scripts/plot_report.py ("" = none)
  std::string plot_name = "bag";
  bool gyro_only = false;
  double elapsed_s = 0.0;  ///< wall time of the run, scoring left out [s]
  double scoring_s = 0.0;  ///< wall time of the ground-truth scoring [s]
  double crop_ratio = 0.0;
};

/// The report JSON: counters, timings, jitter that needs no ground truth
/// and, with a scorer, eval::Scorecard's ground-truth figures for the input
/// and the output (the true head centre and far-background directions
/// mapped through each frame's exact warp, as steadiface_evaluate scores).
/// Also writes the plot trajectories when `plot_dir` is set.
std::string MakeReport(const ReportInputs& r, const BagSink& sink,
                       const steadiface_ros::WrapperStatus& ws);

/// The per-frame pose CSV of --trajectory (full precision).
void WriteTrajectory(const std::string& path, const BagSink& sink);

}  // namespace steadiface_bag
