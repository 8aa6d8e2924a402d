#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/common/status.h"
#include "steadiface_core/composite/layer_homography.h"
#include "steadiface_core/layered/subject_region.h"

namespace steadiface {

/// Options of the subject matte: which output pixels show the subject
/// (face, hair, neck, shoulders), in the background layer's view.
struct SubjectMatteOptions {
  /// The evidence is gathered at 1/scale of the output's resolution [-].
  int scale = 4;
  /// The matte may reach this far beyond the subject region's outline (the
  /// landmarks' head, neck and shoulders) [jaw widths].
  double search_jaw_widths = 0.5;
  /// The landmark prior's softness at the region's outline: its log-odds
  /// change by one per this distance [jaw widths].
  double prior_softness = 0.2;
  /// Colour difference from the background plate at which the plate's
  /// evidence is neutral: below it the pixel is the scene, above it the
  /// subject [grey levels].
  double plate_level = 18.0;
  /// Motion evidence: how much a pixel's change in the background layer
  /// must exceed its change in the subject layer (the subject stands still
  /// in the subject layer, the scene in the background layer) for one unit
  /// of log-odds [grey levels].
  double motion_level = 10.0;
  /// The motion evidence is summed over frames in the subject layer's view
  /// (where the subject stands still), each frame's decaying by this factor
  /// per frame [-].
  double motion_memory = 0.85;
  /// Outside the landmarks' region, the plate takes pixels whose log-odds
  /// are below minus this even where nothing moved (plain walls; elsewhere
  /// it needs the motion evidence) [-].
  double plate_confidence = 4.0;
  /// The plate also takes a pixel whose spot in the subject layer's view
  /// (where the subject stands still) the matte has held below 0.018 for
  /// this many frames in a row: the scene, textured or plain (0: off)
  /// [frames].
  int absent_frames = 8;
  /// Weight of the online colour model's log-likelihood ratio [-].
  double colour_weight = 0.7;
  /// Weight of the previous frame's log-odds, moved with the subject [-].
  double temporal = 0.5;
  /// The edge refinement (a fast guided filter on the background layer's
  /// picture): radius [output px] and regularizer [-].
  int edge_radius_px = 8;
  double edge_eps = 0.002;
};

Status ValidateSubjectMatteOptions(const SubjectMatteOptions& options);

/// What a frame's matte was built from, for the compositor.
struct MatteInputs {
  /// The background and subject layers' output images and views.
  cv::Mat background, subject;
  LayerView background_view, subject_view;
  /// The subject region, in the background layer's output pixels.
  SubjectRegion region;
  /// The background plate as the background layer sees it, at the matte's
  /// low resolution over `roi` (SubjectMatte::LowRoi; colour, validity in
  /// [0, 1]); empty when there is none.
  cv::Mat plate, plate_valid;
  /// Where the matte may reach (SubjectMatte::Roi) [output px].
  cv::Rect roi;
};

/// The subject's matte in the background layer's view: per frame and
/// causally, at low resolution, the log-odds of
/// - the landmark prior (the subject region: head with hair, neck,
///   shoulders; certain inside the face),
/// - the disagreement with the background plate,
/// - the motion: the scene stands still in the background layer and the
///   subject in the subject layer, so a pixel that changed less in the
///   subject layer than in the background layer since the last frame is
///   the subject's; summed over recent frames in the subject layer's view,
/// - an online colour model of subject against scene,
/// - the previous frame's log-odds, moved with the subject,
/// then refined at output resolution at the edges the picture shows (a
/// fast guided filter), so a hair edge stays soft. Not thread-safe.
class SubjectMatte {
 public:
  explicit SubjectMatte(const SubjectMatteOptions& options);
  void Reset();
  /// The rectangle of the output (background view) that the matte may
  /// cover for `region` (empty without a usable region).
  cv::Rect Roi(const SubjectRegion& region, const cv::Size& output) const;
  /// `roi` at the matte's low resolution (clipped to the low picture `small`).
  cv::Rect LowRoi(const cv::Rect& roi, const cv::Size& small) const;
  int scale() const { return options_.scale; }
  /// The matte (CV_32F in [0, 1]) over *active, the part of in.roi where the
  /// subject may be (empty: nowhere); zero elsewhere.
  void Estimate(const MatteInputs& in, cv::Rect* active, cv::Mat* matte);
  /// Where the last Estimate knew the scene to be (CV_32F, 1 or 0, at low
  /// resolution over low_roi()): beyond the search, seen standing still in
  /// the background layer while moving in the subject layer, confidently
  /// the scene outside the landmarks' region, or where the subject has long
  /// been absent in its own layer's view. Only there may the plate learn.
  const cv::Mat& scene_known_low() const { return scene_known_low_; }
  const cv::Rect& low_roi() const { return low_roi_; }

 private:
  struct LowRes;  // this frame's low-resolution pictures over the roi
  // The motion evidence of this frame over the low roi (NaN where unknown);
  // its sum over recent frames, kept in the subject layer's view, over the
  // low roi; all evidence's log-odds and where the scene is known.
  cv::Mat MotionEvidence(const MatteInputs& in, const LowRes& low) const;
  cv::Mat AccumulateMotion(const MatteInputs& in, const LowRes& low, const cv::Mat& lm);
  void Evidence(const MatteInputs& in, const LowRes& low, const cv::Mat& lm,
                const cv::Mat& accumulated, cv::Mat* logodds, cv::Mat* verified) const;
  // Counts, in the subject layer's view, the frames each spot has been
  // without the subject, and adds to *verified the pixels whose spot has
  // been so for absent_frames.
  void VerifyLongAbsent(const MatteInputs& in, const LowRes& low, const cv::Mat& logodds,
                        cv::Mat* verified);
  // The log-odds into the refined full-resolution matte over *active.
  void Refine(const MatteInputs& in, const LowRes& low, const cv::Mat& logodds, cv::Rect* active,
              cv::Mat* matte) const;
  void RefineEdges(const cv::Mat& picture, const cv::Rect& low_roi, const cv::Rect& active,
                   const cv::Mat& mean_a, const cv::Mat& mean_b, const cv::Mat& edge,
                   cv::Mat* matte) const;
  void Remember(const MatteInputs& in, const cv::Mat& logodds, const LowRes& low,
                const cv::Mat& verified);
  float ColourLogRatio(const uchar* px, int cn) const;

  const SubjectMatteOptions options_;
  // The previous frame: the low-resolution grey pictures of both layers
  // (whole output), the background view, the log-odds over its low roi and
  // where the region's head was.
  bool has_previous_ = false;
  cv::Mat previous_background_, previous_subject_;
  LayerView previous_view_;
  cv::Mat previous_logodds_;
  cv::Rect previous_low_roi_;
  Eigen::Vector2d previous_head_ = Eigen::Vector2d::Zero();
  // Colour histograms, subject and scene (8 levels per channel).
  std::vector<float> subject_hist_, scene_hist_;
  cv::Mat scene_known_low_;
  cv::Rect low_roi_;
  cv::Mat accumulated_;  // motion evidence, subject layer's view, low resolution
  cv::Mat absent_;       // frames without the subject (CV_8U), the same
};

}  // namespace steadiface
