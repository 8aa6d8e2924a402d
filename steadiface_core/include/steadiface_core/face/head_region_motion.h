#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace steadiface {

/// How HeadRegionMotion measures a region's motion.
struct HeadRegionMotionOptions {
  /// Corners sought in the region (Shi-Tomasi) [-].
  int max_features = 80;
  /// Fewer tracks than this that agree with their median: no measurement [-].
  int min_inliers = 10;
  /// A region wider than this is tracked on a copy scaled down to it, so a
  /// large head costs what a small one does [px].
  double max_region_px = 160.0;
  /// A track whose backward track misses its start by more is dropped
  /// [px of the tracked copy].
  double max_forward_backward_px = 0.7;
  /// A track agrees with the median shift within this share of the region's
  /// width, and at least 1.5 px [-].
  double inlier_share = 0.04;
  /// The search reaches this share of the region's size beyond it [-].
  double search_margin = 0.6;
};

/// The tracks of one region from the previous frame into this one.
struct RegionFlow {
  /// Where each track starts, in the previous frame [px].
  std::vector<Eigen::Vector2d> from;
  /// Its shift into this frame [px]; only tracks that agree with the median.
  std::vector<Eigen::Vector2d> shift;
  /// The mean of `shift` [px].
  Eigen::Vector2d mean_shift = Eigen::Vector2d::Zero();
  /// The agreeing tracks' share of those that passed the forward-backward
  /// check [-].
  double inlier_share = 0.0;
};

/// The image motion of one region (a head) between consecutive frames,
/// from sparse pyramidal Lucas-Kanade tracks with a forward-backward check
/// and the median of their shifts. It keeps only the grey crop around the
/// last region (the region grown by search_margin, at most max_region_px
/// wide before the margin), never a whole frame.
/// Not thread-safe.
class HeadRegionMotion {
 public:
  explicit HeadRegionMotion(const HeadRegionMotionOptions& options = {})
      : options_(options) {}

  /// Keeps the crop of `grey` around `region` [px] for the next Track.
  void Remember(const cv::Mat& grey, const cv::Rect2d& region);
  /// Where the camera's own rotation moves a still point seen at a pixel
  /// of the previous frame, in this one (the gyro, each row at its time).
  using CameraShift = std::function<Eigen::Vector2d(const Eigen::Vector2d& from_px)>;

  /// The remembered region's tracks into `grey`, those that agree with
  /// their median shift. With `camera` (optional), each shift is taken
  /// beyond the camera's rotation (rolling shutter included), so that the
  /// flow is the region's own motion. False when there is no remembered
  /// region or fewer than min_inliers tracks agree (or under half of those
  /// tracked). `min_inliers` > 0 replaces the options' for this call.
  bool Track(const cv::Mat& grey, RegionFlow* flow, const CameraShift& camera = {},
             int min_inliers = 0) const;
  void Clear();
  bool ready() const { return !cut_pixels_.empty(); }

 private:
  // cut_pixels_ scaled by scale_ (computed on the first Track).
  const cv::Mat& Crop() const;

  const HeadRegionMotionOptions options_;
  cv::Mat cut_pixels_;            // grey around region_, as cut from the frame
  mutable cv::Mat crop_;          // ... scaled by scale_ (Crop)
  cv::Rect cut_;                  // where crop_ was cut from the frame [px]
  cv::Size crop_size_;            // crop_'s size: cut_ scaled by scale_ [px]
  double scale_ = 1.0;            // crop_ px per frame px
  cv::Rect2d region_;             // the region in the frame [px]
};

}  // namespace steadiface
