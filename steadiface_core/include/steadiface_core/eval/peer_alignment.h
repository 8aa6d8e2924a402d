#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/common/status.h"

namespace steadiface {
namespace eval {

/// How a peer's output frame is put back onto the input frame it was made
/// from (AlignPeerFrame).
struct PeerAlignmentOptions {
  /// Corners sought in the input frame [count].
  int max_corners = 500;
  /// Their minimum quality, relative to the strongest corner [-].
  double corner_quality = 0.005;
  /// Their minimum spacing [px].
  double corner_spacing_px = 8.0;
  /// Lucas-Kanade window side [px] and pyramid levels [-].
  int lk_window_px = 21;
  int lk_levels = 3;
  /// A track is kept when tracking it back lands within this of its
  /// start [px].
  double forward_backward_px = 0.3;
  /// RANSAC inlier threshold of the similarity fit [px].
  double ransac_px = 0.75;
  /// Fewer inliers than this fail the frame [count].
  int min_inliers = 40;
};

/// One frame's alignment: output px = H * input px.
struct PeerAlignment {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  int inliers = 0;
  /// RMS distance of the inliers from the fit [px].
  double rms_px = 0.0;
};

/// The similarity (rotation, uniform scale, translation) that maps the
/// input frame onto a peer stabilizer's output frame of the same instant,
/// fitted to the pixels themselves: ffmpeg's vid.stab and deshake move each
/// whole frame by one such transform, so the simulator's true head and
/// scene can then be scored through it exactly (FrameWarp::kHomography)
/// instead of being re-measured from the output video.
///
/// `guess` (output px from input px) seeds the search; the output is
/// resampled through it so that the tracks only have to find what is
/// left (a zoom of 1.43 defeats Lucas-Kanade's translation model; what the
/// guess leaves over does not), in a lenient round and a strict one. With no
/// guess (`has_guess` false), or when the guess's rounds fail, the guess is
/// found from ORB matches. Corners come from the whole input frame:
/// the transform is global, so subject and scene agree. Pixels the peer
/// filled from elsewhere (vid.stab's crop=keep borders) fail the tracks
/// or the fit. Both frames 8-bit grey, the same size.
Status AlignPeerFrame(const cv::Mat& input_grey, const cv::Mat& output_grey,
                      const Eigen::Matrix3d& guess, bool has_guess,
                      const PeerAlignmentOptions& options, PeerAlignment* out);

}  // namespace eval
}  // namespace steadiface
