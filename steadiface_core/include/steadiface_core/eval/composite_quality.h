#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/video/background_segm.hpp>

#include "steadiface_core/common/status.h"
#include "steadiface_core/composite/background_plate.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"
#include "steadiface_core/warp/warper.h"

namespace steadiface {
namespace eval {

/// The composite's own figures against the simulator's truth.
struct CompositeQualityScore {
  int frames = 0;          ///< frames with the subject in view and a matte
  /// IoU of the matte (>= 0.5) with the true subject (coverage >= 0.5) in
  /// the background layer's view, outside a band of edge_band_px around
  /// the true outline: mean and worst frame.
  double matte_iou_mean = NAN, matte_iou_min = NAN;
  int matte_iou_min_frame = -1;
  /// The worst frame after the first half second (the matte's evidence
  /// needs motion, a plate and colours to build up), and where.
  double matte_iou_min_settled = NAN;
  int matte_iou_min_settled_frame = -1;
  /// Mean absolute error of the plate against the true scene behind the
  /// subject, where the plate filled the output (weight >= 0.5) [grey
  /// levels, mean over channels]; the pixels it was measured on.
  double plate_mae = NAN;
  double plate_pixels = 0.0;
  /// The same plate built from the truth (the scene rendered without the
  /// subject, taken where the true subject is not), on the same pixels where
  /// it holds them: what registration, resampling and the pixels' age cost
  /// alone, the floor of plate_mae [grey levels]; the pixels it covered.
  double ideal_plate_mae = NAN;
  double ideal_plate_pixels = 0.0;
  /// Share of the uncovered pixels the fallback filled [0-1].
  double fallback_share = NAN;
  /// End to end where the subject truly uncovered the scene (the true
  /// subject covers the pixel in the background layer's view, coverage
  /// >= 0.95, and not in the subject layer's, <= 0.05): the output against the true scene, whatever filled
  /// it (plate, fallback, or a matte error) [grey levels]; the pixels.
  double uncovered_mae = NAN;
  double uncovered_pixels = 0.0;
  /// The matte's mean per-frame change over the pixels it covers on either
  /// frame [0-1], and the true subject's for comparison.
  double matte_change = NAN, truth_change = NAN;
  /// OpenCV's background subtractors on the background layer's picture (the
  /// scene stands still there, so what moves is the subject): their
  /// foreground's IoU with the true subject, as the matte's, mean over the
  /// same frames (the library alternative to the matte's evidence).
  double mog2_iou_mean = NAN, knn_iou_mean = NAN;
  /// The matte's outline against the truth's: the mean distance of its edge
  /// pixels from the true outline [px], mean over frames, and the largest
  /// per-frame step of that distance [px].
  double edge_error_px = NAN, edge_max_step_px = NAN;
};

/// Scores a composite run's mattes and plates against the simulator's true
/// subject coverage and the scene rendered without the subject, both warped
/// by the background layer's pose exactly as the pipeline warps the frame.
class CompositeQuality {
 public:
  static Status Create(const sim::Simulator& sim, const Pipeline& pipeline,
                       std::unique_ptr<CompositeQuality>* out);
  /// Frame `index` (the rendered `input`) after `pipeline` processed it
  /// into `frame`.
  Status Add(int index, const Pipeline& pipeline, const PipelineFrame& frame,
             const cv::Mat& input);
  CompositeQualityScore Compute() const;
  /// Writes every `every`-th frame to `<prefix>_<frame>.png`: the output,
  /// the matte (red where it misses the true subject, blue where it covers
  /// scene) and the plate's use, side by side. Empty prefix: none.
  void DumpFrames(const std::string& prefix, int every) {
    dump_prefix_ = prefix;
    dump_every_ = std::max(1, every);
  }

  /// Pixels within this distance of the true outline are not scored for
  /// IoU [px].
  static constexpr int kEdgeBandPx = 3;

 private:
  explicit CompositeQuality(const sim::Simulator& sim) : sim_(sim) {}
  // Add's pieces: the matte's IoU and outline; the plate's and the ideal
  // plate's errors; the debug picture.
  void AddMatte(int index, const cv::Mat& truth, const cv::Mat& matte);
  // The subtractors' foreground on the background layer's picture.
  void AddSubtractors(const cv::Mat& truth, const cv::Mat& background_picture);
  void AddPlate(const Compositor& c, const CompositeReport& r, const cv::Mat& truth,
                const cv::Mat& scene_out);
  void Dump(int index, const Compositor& c, const PipelineFrame& f, const cv::Mat& truth,
            const cv::Mat& matte, const cv::Mat& scene_out) const;
  const sim::Simulator& sim_;
  std::unique_ptr<Warper> warper_;
  std::unique_ptr<BackgroundPlate> ideal_plate_;
  int plate_distance_px_ = 3;
  float plate_below_ = 0.1f;
  double ideal_error_ = 0.0, ideal_pixels_ = 0.0;
  std::vector<double> iou_, edge_, mog2_iou_, knn_iou_;
  cv::Ptr<cv::BackgroundSubtractor> mog2_, knn_;
  std::vector<int> iou_frames_;
  double plate_error_ = 0.0, plate_pixels_ = 0.0;
  double uncovered_error_ = 0.0, uncovered_pixels_ = 0.0;
  double uncovered_ = 0.0, fallback_ = 0.0;
  double change_ = 0.0, truth_change_ = 0.0;
  int changes_ = 0;
  cv::Mat previous_, previous_truth_;
  std::string dump_prefix_;
  int dump_every_ = 15;
};

}  // namespace eval
}  // namespace steadiface
