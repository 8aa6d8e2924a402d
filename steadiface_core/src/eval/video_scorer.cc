#include "steadiface_core/eval/video_scorer.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "steadiface_core/common/high_pass_rms.h"
#include "steadiface_core/common/percentile.h"
#include "steadiface_core/eval/ffmpeg_baseline.h"

namespace steadiface {
namespace eval {

Status VideoScorer::Create(const CameraIntrinsics& intrinsics, const VideoScorerOptions& options,
                           std::unique_ptr<VideoScorer>* out) {
  if (!(options.fps > 0.0) || !(options.highpass_hz >= 0.0) || options.max_features < 1 ||
      options.min_features < 1 || !(options.face_exclusion_scale >= 1.0)) {
    return Status::Error("VideoScorerOptions: fps > 0, highpass_hz >= 0, max_features >= 1, "
                         "min_features >= 1 and face_exclusion_scale >= 1 required");
  }
  CameraModel model;
  Status s = CameraModel::Create(intrinsics, CameraModelOptions(), &model);
  if (!s.ok()) return s;
  std::unique_ptr<VideoScorer> v(new VideoScorer(options));
  s = FaceTracker::Create(model, options.face, &v->tracker_);
  if (!s.ok()) return s;
  *out = std::move(v);
  return Status::Ok();
}

Status VideoScorer::Add(const cv::Mat& frame) {
  if (frame.empty() || frame.depth() != CV_8U ||
      (frame.channels() != 1 && frame.channels() != 3)) {
    return Status::Error("VideoScorer: frame must be 8-bit with 1 or 3 channels");
  }
  const double dt = 1.0 / options_.fps;
  const Time stamp = Time(FromSeconds(static_cast<double>(head_.size()) * dt));
  FaceInfo info;
  Status s = tracker_->Process(frame, stamp, nullptr, nullptr, &info);
  if (!s.ok()) return s;
  head_.push_back(info.valid ? info.centre_px
                             : Eigen::Vector2d(std::nan(""), std::nan("")));

  cv::Mat gray;
  if (frame.channels() == 3) {
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = frame.clone();
  }
  Eigen::Vector2d bg = background_.empty() ? Eigen::Vector2d::Zero() : background_.back();
  if (!prev_gray_.empty() && prev_gray_.size() == gray.size()) {
    // Corners of the previous frame outside the (enlarged) face box.
    cv::Mat mask(prev_gray_.size(), CV_8UC1, cv::Scalar(255));
    if (prev_face_) {
      const cv::Point2d c = (prev_face_box_.tl() + prev_face_box_.br()) * 0.5;
      const double k = options_.face_exclusion_scale;
      const cv::Size2d sz(prev_face_box_.width * k, prev_face_box_.height * k);
      cv::rectangle(mask, cv::Rect2d(c.x - sz.width / 2, c.y - sz.height / 2, sz.width, sz.height),
                    cv::Scalar(0), cv::FILLED);
    }
    std::vector<cv::Point2f> p0, p1;
    cv::goodFeaturesToTrack(prev_gray_, p0, options_.max_features, 0.01, 8.0, mask);
    std::vector<double> dx, dy;
    if (static_cast<int>(p0.size()) >= options_.min_features) {
      std::vector<uchar> status;
      std::vector<float> err;
      cv::calcOpticalFlowPyrLK(prev_gray_, gray, p0, p1, status, err, cv::Size(21, 21), 3);
      for (size_t i = 0; i < p0.size(); ++i) {
        if (!status[i]) continue;
        dx.push_back(p1[i].x - p0[i].x);
        dy.push_back(p1[i].y - p0[i].y);
      }
    }
    if (static_cast<int>(dx.size()) >= options_.min_features) {
      if (!bg.allFinite()) bg.setZero();  // a new run after a lost track
      bg += Eigen::Vector2d(Percentile(dx, 0.5), Percentile(dy, 0.5));
    } else {
      bg = Eigen::Vector2d(std::nan(""), std::nan(""));
    }
  }
  background_.push_back(bg);
  prev_gray_ = gray;
  prev_face_ = info.valid;
  prev_face_box_ = info.box;
  return Status::Ok();
}

double VideoScorer::face_fraction() const {
  if (head_.empty()) return 0.0;
  int n = 0;
  for (const auto& h : head_) n += h.allFinite() ? 1 : 0;
  return static_cast<double>(n) / head_.size();
}

Score VideoScorer::Compute() const {
  Score sc;
  sc.frames = static_cast<int>(head_.size());
  sc.cropping = sc.distortion = sc.undefined_fraction = std::nan("");
  sc.head_jitter_px = sc.background_jitter_px = std::nan("");
  sc.head_stability = sc.background_stability = std::nan("");
  if (sc.frames == 0 || prev_gray_.empty()) return sc;
  const double diag = std::hypot(prev_gray_.cols, prev_gray_.rows);
  const size_t min_run = static_cast<size_t>(std::max(16.0, options_.fps));  // >= 1 s
  const std::vector<Eigen::Vector2d> head = Scorecard::LongestFiniteRun(head_);
  if (head.size() >= min_run) {
    sc.head_jitter_px = HighPassRms(head, options_.fps, options_.highpass_hz);
    sc.head_stability = Scorecard::Stability(head);
  }
  sc.head_jitter_frac = sc.head_jitter_px / diag;
  // A lost background track breaks the integration: score the longest run
  // (after a break the trajectory restarts from NaN, so runs never mix).
  const std::vector<Eigen::Vector2d> bg = Scorecard::LongestFiniteRun(background_);
  if (bg.size() >= min_run) {
    sc.background_jitter_px = HighPassRms(bg, options_.fps, options_.highpass_hz);
    sc.background_stability = Scorecard::Stability(bg);
  }
  sc.background_jitter_frac = sc.background_jitter_px / diag;
  return sc;
}

Status ScoreVideoFile(const std::string& path, const VideoScorerOptions& options,
                      VideoFileScore* out) {
  std::unique_ptr<VideoScorer> scorer;
  const Status s = ReadVideo(
      path,
      [&](const cv::Mat& f) {
        if (!scorer) {
          CameraIntrinsics in;
          in.width = f.cols;
          in.height = f.rows;
          in.fx = in.fy = 0.8 * f.cols;  // only sizes the face search
          in.cx = 0.5 * f.cols;
          in.cy = 0.5 * f.rows;
          const Status c = VideoScorer::Create(in, options, &scorer);
          if (!c.ok()) return c;
        }
        return scorer->Add(f);
      },
      &out->width, &out->height);
  if (!s.ok()) return s;
  if (!scorer) return Status::Error("no frame in '" + path + "'");
  out->score = scorer->Compute();
  out->face_fraction = scorer->face_fraction();
  return Status::Ok();
}

}  // namespace eval
}  // namespace steadiface
