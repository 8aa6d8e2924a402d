#include "steadiface_core/eval/peer_alignment.h"

#include <cmath>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace steadiface {
namespace eval {
namespace {

Eigen::Matrix3d FromAffine(const cv::Mat& A) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) H(r, c) = A.at<double>(r, c);
  }
  return H;
}

// A first similarity from ORB matches (scale-invariant enough for a peer's
// zoom), for the first frame or one whose seeded tracks failed.
Status OrbGuess(const cv::Mat& in, const cv::Mat& out, Eigen::Matrix3d* H) {
  cv::Ptr<cv::ORB> orb = cv::ORB::create(2000);
  std::vector<cv::KeyPoint> ki, ko;
  cv::Mat di, dout;
  orb->detectAndCompute(in, cv::noArray(), ki, di);
  orb->detectAndCompute(out, cv::noArray(), ko, dout);
  if (di.empty() || dout.empty()) return Status::Error("no ORB features");
  cv::BFMatcher matcher(cv::NORM_HAMMING, true);
  std::vector<cv::DMatch> matches;
  matcher.match(di, dout, matches);
  std::vector<cv::Point2f> pi, po;
  for (const cv::DMatch& m : matches) {
    pi.push_back(ki[m.queryIdx].pt);
    po.push_back(ko[m.trainIdx].pt);
  }
  if (pi.size() < 20) return Status::Error("too few ORB matches");
  const cv::Mat A =
      cv::estimateAffinePartial2D(pi, po, cv::noArray(), cv::RANSAC, 3.0);
  if (A.empty()) return Status::Error("no similarity fits the ORB matches");
  *H = FromAffine(A);
  return Status::Ok();
}

// The input's `corners` tracked into the output resampled through `G`
// (back), and back again: the input and output points of those that return
// within `fb_px`.
void SeededTracks(const cv::Mat& in, const cv::Mat& back,
                  const std::vector<cv::Point2f>& corners,
                  const Eigen::Matrix3d& G, const PeerAlignmentOptions& o,
                  double fb_px, std::vector<cv::Point2f>* pi,
                  std::vector<cv::Point2f>* po) {
  if (corners.empty()) return;
  std::vector<cv::Point2f> fwd, bwd;
  std::vector<uchar> st1, st2;
  std::vector<float> err;
  const cv::Size win(o.lk_window_px, o.lk_window_px);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                              30, 0.01);
  cv::calcOpticalFlowPyrLK(in, back, corners, fwd, st1, err, win, o.lk_levels,
                           term);
  cv::calcOpticalFlowPyrLK(back, in, fwd, bwd, st2, err, win, o.lk_levels,
                           term);
  for (size_t k = 0; k < corners.size(); ++k) {
    if (!st1[k] || !st2[k]) continue;
    const cv::Point2f d = bwd[k] - corners[k];
    if (std::hypot(d.x, d.y) > fb_px) continue;
    const Eigen::Vector3d q = G * Eigen::Vector3d(fwd[k].x, fwd[k].y, 1.0);
    if (!(std::abs(q.z()) > 1e-9)) continue;
    pi->push_back(corners[k]);
    po->push_back(cv::Point2f(q.x() / q.z(), q.y() / q.z()));
  }
}

// One round: the output resampled through G (back(p) = out(G p)), the
// input's corners tracked into it and back, a similarity fitted to those
// within `fb_px` with RANSAC at `ransac_px`.
Status Refine(const cv::Mat& in, const cv::Mat& out,
              const std::vector<cv::Point2f>& corners, const Eigen::Matrix3d& G,
              const PeerAlignmentOptions& o, double fb_px, double ransac_px,
              PeerAlignment* a) {
  cv::Mat Gcv, back;
  cv::eigen2cv(G, Gcv);
  cv::warpPerspective(out, back, Gcv, in.size(),
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, 0);
  std::vector<cv::Point2f> pi, po;
  SeededTracks(in, back, corners, G, o, fb_px, &pi, &po);
  if (static_cast<int>(pi.size()) < o.min_inliers) {
    return Status::Error(std::to_string(pi.size()) + " tracks survive");
  }
  std::vector<uchar> inlier;
  const cv::Mat A = cv::estimateAffinePartial2D(pi, po, inlier, cv::RANSAC,
                                                ransac_px, 2000, 0.995, 20);
  if (A.empty()) return Status::Error("no similarity fits the tracks");
  a->H = FromAffine(A);
  a->inliers = 0;
  double s2 = 0.0;
  for (size_t k = 0; k < pi.size(); ++k) {
    if (!inlier[k]) continue;
    const Eigen::Vector3d q = a->H * Eigen::Vector3d(pi[k].x, pi[k].y, 1.0);
    s2 += (q.head<2>() - Eigen::Vector2d(po[k].x, po[k].y)).squaredNorm();
    ++a->inliers;
  }
  if (a->inliers < o.min_inliers || !a->H.allFinite()) {
    return Status::Error(std::to_string(a->inliers) + " inliers");
  }
  a->rms_px = std::sqrt(s2 / a->inliers);
  return Status::Ok();
}

// Two rounds from G: a lenient one that brings G close, a strict one that
// fits what is left.
Status Align(const cv::Mat& in, const cv::Mat& out,
             const std::vector<cv::Point2f>& corners, const Eigen::Matrix3d& G,
             const PeerAlignmentOptions& o, PeerAlignment* a) {
  PeerAlignment rough;
  Status s = Refine(in, out, corners, G, o, 4.0 * o.forward_backward_px,
                    4.0 * o.ransac_px, &rough);
  if (s.ok()) {
    s = Refine(in, out, corners, rough.H, o, o.forward_backward_px, o.ransac_px,
               a);
  }
  return s;
}

}  // namespace

Status AlignPeerFrame(const cv::Mat& input_grey, const cv::Mat& output_grey,
                      const Eigen::Matrix3d& guess, bool has_guess,
                      const PeerAlignmentOptions& options, PeerAlignment* out) {
  if (input_grey.empty() || input_grey.type() != CV_8UC1 ||
      output_grey.type() != CV_8UC1 ||
      input_grey.size() != output_grey.size()) {
    return Status::Error("AlignPeerFrame: two 8-bit grey frames of one size");
  }
  // The input's corners, found once for every round.
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(input_grey, corners, options.max_corners,
                          options.corner_quality, options.corner_spacing_px);
  PeerAlignment a;
  Status s = Status::Error("no guess");
  if (has_guess && guess.allFinite()) {
    s = Align(input_grey, output_grey, corners, guess, options, &a);
  }
  if (!s.ok()) {
    // No guess, or it was too far off: ORB's.
    Eigen::Matrix3d G;
    s = OrbGuess(input_grey, output_grey, &G);
    if (s.ok()) s = Align(input_grey, output_grey, corners, G, options, &a);
  }
  if (!s.ok()) return Status::Error("AlignPeerFrame: " + s.message());
  *out = a;
  return Status::Ok();
}

}  // namespace eval
}  // namespace steadiface
