#pragma once

// What steadiface_evaluate writes besides its scores' table: the per-frame
// trajectory, the reach tube and the feasible set for the analysis scripts,
// the 15-frame average, and the formatting of the table, report.json and the
// composite's quality rows. Private to eval/evaluation.cc.

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/eval/composite_quality.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace eval {

/// Per frame: the scorecard's sample (true head in and out, background,
/// virtual and real angles, offset, crop) and the stabilizer's own record
/// (w_f, the protrusion search, previous warp; nan without a stabilizer).
Status WriteTrajectory(const std::string& path, const std::vector<Scorecard::Sample>& samples,
                       const std::vector<StabilizerFrame>& frames);

/// Per frame of a layered run: the time, the true head centre through the
/// background layer's pose and whether it is in view [output px], and the
/// radius H was held within there (0: none) [output px]; for
/// scripts/analysis/reach_bound.py.
Status WriteReachTube(const sim::Simulator& sim, const PipelineOptions& po,
                      const std::vector<StabilizerFrame>& frames, const std::string& path);

/// Per frame: the time and the radii of FeasibleOffsets in 72 directions
/// [input px]; with max_roll > 0 also <path>_roll.csv for a window that
/// also rolls (every 0.025 rad within +-max_roll) and the true head's move.
Status WriteFeasibleSet(const CameraIntrinsics& intrinsics, const PipelineOptions& po,
                        const std::vector<StabilizerFrame>& frames, const std::string& path,
                        const std::vector<Eigen::Vector2d>& heads, double max_roll);

/// --average15 N: writes frame N (<prefix>_frame.png) and the mean of frames
/// N-7 .. N+7 (<prefix>_average15.png): a steady background or face is
/// sharp in the average, one that swims is blurred.
class FrameAverager {
 public:
  FrameAverager(std::string prefix, int centre) : prefix_(std::move(prefix)), centre_(centre) {}
  Status Add(const cv::Mat& frame);

 private:
  std::string prefix_;
  int centre_ = 0, index_ = 0;
  cv::Mat sum_;
};

/// What one (preset, method) run reports beside its score.
struct RunFigures {
  double solver_ms = NAN, face_ms = NAN, peer_ms = NAN;  ///< medians; peer: ffmpeg's per frame
  double face_fraction = NAN;  ///< frames whose face entered E_f
  bool approximate = false;    ///< scored from the output video
  /// A peer scored through per-frame alignments of its output to the input
  /// (AlignPeerFrame): the worst frame's RMS fit residual [px] and its
  /// fewest inliers.
  bool aligned = false;
  double alignment_rms_px = NAN;
  int alignment_min_inliers = -1;
  double duration_s = 0.0;
  std::string options_conflict;  ///< OptionsConflict of the run's options
};

/// The markdown table's header, and one run's row.
std::string TableHeader();
std::string TableRow(const std::string& preset, const std::string& method, const Score& sc,
                     const RunFigures& run);
/// One run's object in report.json's "results" (no separator).
std::string JsonResult(const std::string& preset, const std::string& method, const Score& sc,
                       const RunFigures& run);
/// A number for report.json: null when not finite.
std::string JsonNumber(double v);

/// One preset's composite figures: a markdown row and a CSV row.
std::pair<std::string, std::string> CompositeRow(const std::string& preset,
                                                 const CompositeQualityScore& q);
/// The composite's table (to `out`) and composite_quality.csv, from the rows.
void WriteCompositeTable(const std::vector<std::pair<std::string, std::string>>& rows,
                         const std::string& csv_path, std::ostream& out);

}  // namespace eval
}  // namespace steadiface
