#pragma once

#include <deque>
#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/common/status.h"
#include "steadiface_core/composite/background_plate.h"
#include "steadiface_core/composite/layer_homography.h"
#include "steadiface_core/composite/subject_matte.h"
#include "steadiface_core/layered/subject_region.h"
#include "steadiface_core/camera/output_geometry.h"

namespace steadiface {

/// Options of the composite warp (warp mode composite).
struct CompositeOptions {
  /// The subject's matte.
  SubjectMatteOptions matte;
  /// The background plate.
  BackgroundPlateOptions plate;
  /// The plate takes pixels whose matte is below this [0-1] ...
  double plate_below = 0.1;
  /// ... within this distance (a subject's soft edge, hair, is a mix of
  /// subject and scene) [output px].
  int plate_distance_px = 3;
  /// The plate learns every this-many-th of its rows per frame, in turn
  /// (1: all every frame; 2 halves the plate's update time, and bob's fill
  /// falls back to the subject layer on 0.58 of the uncovered pixels instead
  /// of 0.47) [count].
  int plate_row_step = 1;
};

Status ValidateCompositeOptions(const CompositeOptions& options);

/// What the composite did to one frame.
struct CompositeReport {
  bool active = false;  ///< a subject was composited (else: the background layer)
  /// The output rectangles the matte covered, in the background layer's and
  /// in the subject layer's view [output px].
  cv::Rect background_roi, subject_roi;
  /// Pixels the subject uncovered (the background layer shows the subject
  /// there, the composite does not) [px], weighted by the mattes.
  double uncovered_px = 0.0;
  /// Share of them the plate filled, and the fallback's share (the subject
  /// layer's picture, as the global warp would show it) [0-1].
  double plate_share = 0.0;
  double fallback_share = 0.0;
  /// The fresh share of the plate [0-1]; its restarts and reprojections so far.
  double plate_coverage = 0.0;
  int plate_restarts = 0;
  int plate_reprojections = 0;
  /// The rectangle the plate learnt this frame: the matte's roi and where
  /// it was over the plate's lifetime, in this frame's background view
  /// [output px].
  cv::Rect plate_learnt;
  /// Mean matte over the background roi [0-1].
  double matte_mean = 0.0;
  double matte_ms = 0.0, plate_ms = 0.0, blend_ms = 0.0;
};

/// The composite (warp mode composite): the subject, warped by the
/// face-following virtual camera, over the background, warped by the
/// gyro-only one. Where the background layer still shows the subject, the
/// background plate shows the scene instead; where the plate has not seen
/// it, the subject layer's picture is the fallback (the global warp's).
///
///   out = m_s S + (1 - m_s) (B + m_b v (P - B) + m_b (1 - v) (S - B))
///
/// with S, B the two layers' pictures, m_b the matte in the background
/// layer's view, m_s the same matte moved into the subject layer's view,
/// P the plate and v its freshness. Causal; one per stream; not
/// thread-safe.
class Compositor {
 public:
  static Status Create(const OutputGeometry& output, const CompositeOptions& options,
                       std::unique_ptr<Compositor>* out);

  /// Forgets the plate, the matte's memory (time jump, scene change).
  void Reset();

  /// Composes one frame. `subject` and `background` are the two layers'
  /// pictures (8-bit, same size and type), `region` the subject region in
  /// the background layer's view (its blend scales the subject's share),
  /// `time_s` the frame's time. *out may alias `background`.
  Status Compose(const cv::Mat& subject, const LayerView& subject_view, const cv::Mat& background,
                 const LayerView& background_view, const SubjectRegion& region, double time_s,
                 cv::Mat* out);

  const CompositeReport& report() const { return report_; }
  /// The last matte in the background layer's view over
  /// report().background_roi (CV_32F, [0, 1]), and moved into the subject
  /// layer's view over report().subject_roi (CV_8U, 255 = subject).
  const cv::Mat& background_matte() const { return matte_b_; }
  const cv::Mat& subject_matte() const { return matte_s_; }
  /// With KeepPlateUse(true), over the background roi: the plate's weight in
  /// the output, m_b v (1 - m_s) (CV_32F), and the plate as this frame's
  /// background camera saw it where it was looked at (the images' type);
  /// empty otherwise (for scoring and debugging: they cost memory).
  void KeepPlateUse(bool keep) { keep_plate_ = keep; }
  const cv::Mat& plate_weight() const { return plate_weight_; }
  const cv::Mat& plate_sample() const { return plate_sample_; }
  const BackgroundPlate& plate() const { return plate_; }

 private:
  Compositor(const OutputGeometry& output, const CompositeOptions& options);
  // Compose's pieces: the subject's matte in both views, the plate's fill and
  // the blend over the active rectangle (where the matte is); the plate's
  // update over LearnRect.
  void ComposeActive(const cv::Mat& subject, const LayerView& subject_view,
                     const LayerView& background_view, const SubjectRegion& region,
                     const cv::Rect& active, const cv::Mat& raw, cv::Mat* out);
  void UpdatePlate(const cv::Mat& background, const cv::Rect& learn, const cv::Rect& active,
                   const cv::Mat& raw);
  // Where the plate learns this frame: `roi` and the rois of the frames
  // within the plate's lifetime, each moved into `view` (what the subject
  // uncovers lies where it has been, and a roi's rows above or beside this
  // frame's are otherwise never learnt).
  cv::Rect LearnRect(const LayerView& view, const cv::Rect& roi, double time_s);
  // Fills the subject's uncovered pixels of `out` (over the background roi).
  void FillUncovered(const cv::Mat& subject, cv::Mat* out);
  // FillUncovered's row y of the background roi (rows may run in
  // parallel), adding to the uncovered and plate-filled weights.
  void FillRow(const cv::Mat& subject, int y, double* uncovered, double* filled,
               cv::Mat* out);
  // The subject over `out` (over the subject roi).
  void Blend(const cv::Mat& subject, cv::Mat* out);

  const OutputGeometry output_;
  const CompositeOptions options_;
  SubjectMatte matte_;
  BackgroundPlate plate_;
  CompositeReport report_;
  cv::Mat matte_b_, plate_weight_, plate_sample_;
  cv::Mat matte_b8_, matte_s_;  // the matte in 1/255 steps in both views
  // UpdatePlate's scratch (kept: no allocation per frame).
  cv::Mat blocked_, unknown_, unknown_up_;
  // The recent frames' matte rois in their background views (bounded by
  // the plate's lifetime and kMaxRois).
  struct PastRoi {
    double time_s;
    LayerView view;
    cv::Rect roi;
  };
  static constexpr size_t kMaxRois = 256;
  std::deque<PastRoi> past_rois_;
  bool keep_plate_ = false;
  int frame_ = 0;  // frames composed (the plate's row phase)
};

}  // namespace steadiface
