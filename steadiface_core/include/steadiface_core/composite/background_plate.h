#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/composite/layer_homography.h"

namespace steadiface {

/// Options of the background plate: what the scene behind the subject
/// looked like, from recent frames.
struct BackgroundPlateOptions {
  /// The plate reaches this far beyond the output on each side, as a
  /// fraction of the output's width and height [-].
  double margin = 0.15;
  /// A pixel not seen for this long has expired (parallax, light, a
  /// passer-by) [s].
  double max_age_s = 1.5;
  /// Weight of this frame where the plate already holds the pixel (the rest
  /// is the plate's; 1 = newest only) [-].
  double update_rate = 0.5;
  /// A fresh pixel that confirm_frames confirmed is not updated by a value
  /// that differs from it by more than this (a subject's soft edge the
  /// matte let through); it expires after max_age_s if the scene really
  /// changed [grey levels].
  double outlier_level = 40.0;
  /// A fresh pixel turns away a value beyond outlier_level only once this
  /// many consecutive frames have agreed with it; before, such a value
  /// replaces it. A subject's edge the matte let through moves on, and the
  /// scene, standing still in the background layer's view, then replaces
  /// it; 1 = the first value taken is kept while fresh [frames].
  int confirm_frames = 4;
  /// The plate restarts when the background camera has turned by more than
  /// this since the plate's anchor [deg]; below it, the plate is reprojected
  /// once when the view leaves it.
  double reset_angle_deg = 15.0;
  /// Scene cut: the mean absolute difference between this frame's background
  /// and the plate, where both are background, above which the plate
  /// restarts [grey levels].
  double scene_cut_level = 45.0;
};

Status ValidateBackgroundPlateOptions(const BackgroundPlateOptions& options);

/// A plate of the far scene in a world-anchored virtual camera (the
/// background layer's pose at the plate's anchoring, with a margin around
/// the output): colour and the time each pixel was last seen. The background
/// layer's camera is gyro-stabilized, so the far scene stands still in it and
/// what the subject uncovers was seen here a moment earlier. Memory: one
/// image of the output plus its margin, a float time and a byte of agreeing
/// frames per pixel. Causal; one per stream; not thread-safe.
class BackgroundPlate {
 public:
  BackgroundPlate(const OutputGeometry& output,
                  const BackgroundPlateOptions& options);

  /// Forgets everything (time jump, new epoch).
  void Reset();
  /// Starts a frame seen by the background layer's camera `view` at
  /// `time_s`: anchors the plate on the first frame, reprojects it when the
  /// output leaves it, restarts it after a large turn.
  void Begin(const LayerView& view, double time_s);
  /// The plate as the background camera sees it over output rectangle
  /// `roi`: colour (the images' type) and validity (CV_32F in [0, 1]: 1 while
  /// the pixel is fresh, fading to 0 over the last quarter of max_age_s, 0
  /// where never seen).
  void Sample(const cv::Rect& roi, cv::Mat* colour, cv::Mat* valid) const;
  /// The same at `scale` pictures' pixels per output pixel (< 1: smaller).
  void Sample(const cv::Rect& roi, double scale, cv::Mat* colour,
              cv::Mat* valid) const;
  /// The plate at plate pixel (px, py), bilinear, into `colour` (the
  /// images' channels); returns its freshness in [0, 1] (0: not seen,
  /// expired or outside; then `colour` is not written). view_to_plate()
  /// maps output pixels of the current view to plate pixels.
  float SamplePlate(double px, double py, uchar* colour) const;
  const Eigen::Matrix3d& view_to_plate() const { return view_to_plate_; }
  /// Takes this frame's background (`image_roi`, 8-bit, 1-4 channels, output
  /// rectangle `roi`) where `matte_roi` (subject coverage: CV_32F in [0, 1], or
  /// CV_8U in 1/255 steps) is below `background_below`, on every `row_step`-th
  /// plate row from `row_phase` (a caller alternating the phase spreads the
  /// work over frames). Returns false (and restarts the plate) on a scene cut.
  bool Update(const cv::Mat& image_roi, const cv::Mat& matte_roi,
              const cv::Rect& roi, float background_below, int row_step = 1,
              int row_phase = 0);

  /// Fraction of the plate's pixels that are fresh [0-1] (on a 4 px grid).
  double Coverage() const;
  int restarts() const { return restarts_; }
  int reprojections() const { return reprojections_; }
  const cv::Mat& colour() const { return plate_; }
  const BackgroundPlateOptions& options() const { return options_; }
  /// The current frame's time (Begin) [s].
  double now() const { return now_; }
  /// Last time each pixel was seen [s]; -inf where never.
  const cv::Mat& seen() const { return seen_; }

 private:
  // Plate pixel <- output pixel of the current view.
  Eigen::Matrix3d PlateFromView() const {
    return HomographyBetween(anchor_, view_);
  }
  bool ViewInside() const;
  // Update's step over plate row py from x0: `in` is the picture at each of
  // its `width` pixels' view points; a pixel marked in `take` is taken,
  // unless it is a confirmed pixel's outlier (an unconfirmed one is
  // replaced). Writes plate row py only, so rows may run in parallel.
  void UpdateRow(const uchar* in, const uchar* take, int x0, int py, int width,
                 double* diff, int* compared);
  void Reproject();

  const OutputGeometry output_;
  const BackgroundPlateOptions options_;
  const int margin_x_, margin_y_;
  cv::Mat plate_;  // CV_8UC3
  cv::Mat seen_;   // CV_32F
  // CV_8U: frames that agreed with each pixel since it was last replaced
  // (saturating).
  cv::Mat agreed_;
  // Update's scratch: the picture at the learnt plate pixels' view points
  // (at most the plate's size).
  cv::Mat in_;
  bool anchored_ = false;
  LayerView anchor_, view_;
  Eigen::Matrix3d view_to_plate_ = Eigen::Matrix3d::Identity();
  double now_ = 0.0;
  int restarts_ = 0, reprojections_ = 0;
};

}  // namespace steadiface
