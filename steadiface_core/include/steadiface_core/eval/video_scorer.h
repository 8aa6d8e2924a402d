#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/face/face_tracker.h"

namespace steadiface {
namespace eval {

struct VideoScorerOptions {
  /// Frame rate of the video [Hz].
  double fps = 30.0;
  /// High-pass cut-off for jitter [Hz] (as the exact scorecard).
  double highpass_hz = 0.5;
  /// Background corners tracked per frame pair [-].
  int max_features = 300;
  /// The face box enlarged by this is excluded from background tracking [-].
  double face_exclusion_scale = 2.0;
  /// Minimum tracked background features for a frame pair to count [-].
  int min_features = 12;
  /// Face tracking (detection and 68 landmarks) as in the pipeline.
  FaceTrackerOptions face;
};

/// The approximate scoring path for stabilizers that expose no warp (ffmpeg
/// vidstab, deshake, or any video file): the same metric definitions as
/// `Scorecard`, measured on the output frames themselves.
///  - head: the landmark centre C of the face of interest (dlib, the
///    pipeline's tracker without gyro), scored on the longest run of frames
///    with a face (as the exact scorecard does with the true head);
///  - background: KLT tracks of corners outside the (enlarged) face box
///    between consecutive frames; the median displacement per frame pair is
///    integrated into one background trajectory.
/// It is approximate: C is not the true head centre (landmark noise adds
/// jitter), the median track stands for the mean of the true far-background
/// points, and cropping, distortion and undefined pixels are not measured
/// (left NaN). `Score::frames` counts the frames added.
class VideoScorer {
 public:
  static Status Create(const CameraIntrinsics& intrinsics, const VideoScorerOptions& options,
                       std::unique_ptr<VideoScorer>* out);

  /// One output frame (8-bit, 1 or 3 channels, the intrinsics' size).
  Status Add(const cv::Mat& frame);

  Score Compute() const;

  /// Fraction of frames with a validated face [0-1].
  double face_fraction() const;
  /// Per frame: head centre (NaN when no face) and background position [px].
  const std::vector<Eigen::Vector2d>& head() const { return head_; }
  const std::vector<Eigen::Vector2d>& background() const { return background_; }

 private:
  VideoScorer(const VideoScorerOptions& options) : options_(options) {}

  const VideoScorerOptions options_;
  std::unique_ptr<FaceTracker> tracker_;
  cv::Mat prev_gray_;
  cv::Rect2d prev_face_box_;
  bool prev_face_ = false;
  std::vector<Eigen::Vector2d> head_;
  std::vector<Eigen::Vector2d> background_;
};

/// A video file's approximate score (steadiface_score_video).
struct VideoFileScore {
  Score score;
  double face_fraction = 0.0;  ///< frames with a face found [-]
  int width = 0, height = 0;   ///< [px]
};

/// Decodes `path` (any video ffmpeg reads) and scores every frame with a
/// VideoScorer whose camera is a guess from the frame size (fx = 0.8 W: it
/// only sizes the face search).
Status ScoreVideoFile(const std::string& path, const VideoScorerOptions& options,
                      VideoFileScore* out);

}  // namespace eval
}  // namespace steadiface
