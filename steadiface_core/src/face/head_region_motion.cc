// A head region's image motion between frames (sparse KLT, median shift).
#include "steadiface_core/face/head_region_motion.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace steadiface {
namespace {

// `r` grown by `margin` of its size on each side, inside `size`.
cv::Rect Grown(const cv::Rect2d& r, double margin, const cv::Size& size) {
  const cv::Rect2d g(r.x - margin * r.width, r.y - margin * r.height,
                     (1.0 + 2.0 * margin) * r.width, (1.0 + 2.0 * margin) * r.height);
  const cv::Rect i(cv::Point(static_cast<int>(std::floor(g.x)), static_cast<int>(std::floor(g.y))),
                   cv::Point(static_cast<int>(std::ceil(g.x + g.width)),
                             static_cast<int>(std::ceil(g.y + g.height))));
  return i & cv::Rect(0, 0, size.width, size.height);
}

double Median(std::vector<double> v) {
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

}  // namespace

void HeadRegionMotion::Clear() {
  cut_pixels_.release();
  crop_.release();
  region_ = cv::Rect2d();
}

const cv::Mat& HeadRegionMotion::Crop() const {
  // Scaled on first use only: most remembered regions are never tracked
  // (the landmarks fit the next frame), and scaling a large head's crop
  // costs more than copying it.
  if (crop_.empty() && !cut_pixels_.empty()) {
    if (scale_ < 1.0) {
      cv::resize(cut_pixels_, crop_, crop_size_, 0, 0, cv::INTER_AREA);
    } else {
      crop_ = cut_pixels_;
    }
  }
  return crop_;
}

void HeadRegionMotion::Remember(const cv::Mat& grey, const cv::Rect2d& region) {
  Clear();
  if (grey.empty() || grey.type() != CV_8UC1 || !(region.width >= 8.0) ||
      !(region.height >= 8.0)) {
    return;
  }
  // The crop holds the region and the reach of the search around it; the
  // next frame is cut at the same place (Lucas-Kanade pairs equal sizes).
  // A large head is tracked on a copy scaled down to max_region_px: the
  // cost stays that of a small one.
  const cv::Rect c = Grown(region, options_.search_margin, grey.size());
  scale_ = std::min(1.0, options_.max_region_px / region.width);
  const cv::Size size(cvRound(c.width * scale_), cvRound(c.height * scale_));
  if (size.width < 16 || size.height < 16) return;
  grey(c).copyTo(cut_pixels_);
  cut_ = c;
  crop_size_ = size;
  region_ = region;
}

bool HeadRegionMotion::Track(const cv::Mat& grey, RegionFlow* flow, const CameraShift& camera,
                             int min_inliers) const {
  const HeadRegionMotionOptions& o = options_;
  const int min_n = min_inliers > 0 ? min_inliers : o.min_inliers;
  if (cut_pixels_.empty() || grey.empty() || grey.type() != CV_8UC1) return false;
  const cv::Mat& crop = Crop();
  // Corners inside the region's ellipse (the head, not the corners of its
  // box, where the background shows).
  const double k = scale_;
  cv::Mat mask = cv::Mat::zeros(crop.size(), CV_8U);
  const cv::Point2d centre((region_.x + 0.5 * region_.width - cut_.x) * k,
                           (region_.y + 0.5 * region_.height - cut_.y) * k);
  cv::ellipse(mask, cv::Point(cvRound(centre.x), cvRound(centre.y)),
              cv::Size(cvRound(0.5 * region_.width * k), cvRound(0.5 * region_.height * k)), 0.0,
              0.0, 360.0, cv::Scalar(255), cv::FILLED);
  std::vector<cv::Point2f> p0;
  const double spacing = std::max(3.0, region_.width * k / 20.0);
  cv::goodFeaturesToTrack(crop, p0, o.max_features, 0.01, spacing, mask);
  if (static_cast<int>(p0.size()) < min_n) return false;
  // This frame cut where the remembered crop was, at its scale.
  if ((cut_ & cv::Rect(0, 0, grey.cols, grey.rows)) != cut_) return false;
  cv::Mat now;
  if (k < 1.0) {
    cv::resize(grey(cut_), now, crop.size(), 0, 0, cv::INTER_AREA);
  } else {
    now = grey(cut_);
  }
  const std::vector<cv::Point2f>& guess = p0;
  std::vector<cv::Point2f> p1 = p0, back = p0;
  std::vector<uchar> ok1, ok2;
  std::vector<float> err;
  const cv::Size win(15, 15);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  cv::calcOpticalFlowPyrLK(crop, now, p0, p1, ok1, err, win, 3, term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  cv::calcOpticalFlowPyrLK(now, crop, p1, back, ok2, err, win, 3, term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<Eigen::Vector2d> d, from;
  for (size_t i = 0; i < p0.size(); ++i) {
    if (!ok1[i] || !ok2[i]) continue;
    const cv::Point2f fb = back[i] - p0[i];
    if (std::hypot(fb.x, fb.y) > o.max_forward_backward_px) continue;
    const cv::Point2f m = p1[i] - guess[i];
    const Eigen::Vector2d start(p0[i].x / k + cut_.x, p0[i].y / k + cut_.y);  // frame px
    d.emplace_back(Eigen::Vector2d(m.x, m.y) / k -
                   (camera ? camera(start) : Eigen::Vector2d::Zero()));
    from.push_back(start);
  }
  if (static_cast<int>(d.size()) < min_n) return false;
  std::vector<double> dx, dy;
  for (const auto& v : d) {
    dx.push_back(v.x());
    dy.push_back(v.y());
  }
  const Eigen::Vector2d med(Median(dx), Median(dy));
  const double radius = std::max(1.5, o.inlier_share * region_.width);
  RegionFlow f;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < d.size(); ++i) {
    if ((d[i] - med).norm() > radius) continue;
    sum += d[i];
    f.from.push_back(from[i]);
    f.shift.push_back(d[i]);
  }
  const int n = static_cast<int>(f.shift.size());
  if (n < min_n || 2 * n < static_cast<int>(d.size())) return false;
  f.mean_shift = sum / n;
  f.inlier_share = n / static_cast<double>(d.size());
  if (!f.mean_shift.allFinite()) return false;
  *flow = std::move(f);
  return true;
}

}  // namespace steadiface
