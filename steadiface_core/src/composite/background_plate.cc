#include "steadiface_core/composite/background_plate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace steadiface {
namespace {

constexpr float kNever = -std::numeric_limits<float>::infinity();

bool In(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

}  // namespace

Status ValidateBackgroundPlateOptions(const BackgroundPlateOptions& o) {
  if (!In(o.margin, 0.0, 1.0)) return Status::Error("composite.plate: margin must be in [0, 1]");
  if (!In(o.max_age_s, 0.01, 60.0)) {
    return Status::Error("composite.plate: max_age_s must be in [0.01, 60] s");
  }
  if (!In(o.update_rate, 0.01, 1.0)) {
    return Status::Error("composite.plate: update_rate must be in [0.01, 1]");
  }
  if (!In(o.reset_angle_deg, 0.1, 90.0)) {
    return Status::Error("composite.plate: reset_angle_deg must be in [0.1, 90] deg");
  }
  if (!In(o.outlier_level, 1.0, 255.0)) {
    return Status::Error("composite.plate: outlier_level must be in [1, 255]");
  }
  if (!In(o.scene_cut_level, 1.0, 255.0)) {
    return Status::Error("composite.plate: scene_cut_level must be in [1, 255]");
  }
  return Status::Ok();
}

BackgroundPlate::BackgroundPlate(const OutputGeometry& output,
                                 const BackgroundPlateOptions& options)
    : output_(output),
      options_(options),
      margin_x_(static_cast<int>(std::lround(options.margin * output.width()))),
      margin_y_(static_cast<int>(std::lround(options.margin * output.height()))) {
  plate_ = cv::Mat(output.height() + 2 * margin_y_, output.width() + 2 * margin_x_, CV_8UC3,
                   cv::Scalar::all(0));  // retyped on the first image of another type
  seen_ = cv::Mat(plate_.size(), CV_32F, cv::Scalar(kNever));
}

void BackgroundPlate::Reset() {
  plate_.setTo(cv::Scalar::all(0));
  seen_.setTo(cv::Scalar(kNever));
  anchored_ = false;
}

bool BackgroundPlate::ViewInside() const {
  const cv::Rect all(0, 0, plate_.cols, plate_.rows);
  const cv::Rect out(0, 0, output_.width(), output_.height());
  const cv::Rect r = MapRect(PlateFromView(), out, cv::Rect(-100000, -100000, 200000, 200000));
  return !r.empty() && (r & all) == r;
}

void BackgroundPlate::Begin(const LayerView& view, double time_s) {
  view_ = view;
  now_ = time_s;
  if (anchored_) {
    const double angle = 2.0 * std::acos(std::min(1.0, std::abs((view.R * anchor_.R.conjugate()).w())));
    if (angle * 180.0 / M_PI > options_.reset_angle_deg) {
      Reset();
      ++restarts_;
    } else if (!ViewInside()) {
      Reproject();
    }
  }
  if (!anchored_) {
    anchor_ = view;
    anchor_.K(0, 2) += margin_x_;
    anchor_.K(1, 2) += margin_y_;
    anchored_ = true;
  }
}

void BackgroundPlate::Reproject() {
  // The new anchor is the current view (with the margin); old plate pixel <-
  // new plate pixel.
  LayerView next = view_;
  next.K(0, 2) += margin_x_;
  next.K(1, 2) += margin_y_;
  const Eigen::Matrix3d H = HomographyBetween(anchor_, next);
  const cv::Rect all(0, 0, plate_.cols, plate_.rows);
  const cv::Matx33d M = RectMap(H, all, 1.0, all, 1.0);
  cv::Mat plate, seen;
  cv::warpPerspective(plate_, plate, M, plate_.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar::all(0));
  cv::warpPerspective(seen_, seen, M, seen_.size(), cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(kNever));
  plate_ = plate;
  seen_ = seen;
  anchor_ = next;
  ++reprojections_;
}

void BackgroundPlate::Sample(const cv::Rect& roi, cv::Mat* colour, cv::Mat* valid) const {
  // (A plate of another type than the images has never been written: it is
  // all unseen, and its colour is not read.)
  const cv::Rect all(0, 0, plate_.cols, plate_.rows);
  const cv::Matx33d M = RectMap(PlateFromView(), all, 1.0, roi, 1.0);
  cv::warpPerspective(plate_, *colour, M, roi.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar::all(0));
  cv::Mat seen;
  cv::warpPerspective(seen_, seen, M, roi.size(), cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(kNever));
  // Fresh: 1 up to 3/4 of the maximum age, fading to 0 at it.
  const float now = static_cast<float>(now_), max_age = static_cast<float>(options_.max_age_s);
  valid->create(roi.size(), CV_32F);
  for (int y = 0; y < roi.height; ++y) {
    const float* s = seen.ptr<float>(y);
    float* v = valid->ptr<float>(y);
    for (int x = 0; x < roi.width; ++x) {
      const float age = now - s[x];
      v[x] = std::min(1.0f, std::max(0.0f, (max_age - age) / (0.25f * max_age)));
    }
  }
  // The colour is interpolated from the four nearest plate pixels: next to
  // an unseen one it is not the scene's.
  cv::erode(*valid, *valid, cv::Mat());
}

bool BackgroundPlate::Update(const cv::Mat& image_roi, const cv::Mat& matte_roi,
                             const cv::Rect& roi, float background_below) {
  if (image_roi.type() != plate_.type()) {
    plate_ = cv::Mat(plate_.size(), image_roi.type(), cv::Scalar::all(0));
    seen_.setTo(cv::Scalar(kNever));
  }
  const int cn = plate_.channels();
  const cv::Rect all(0, 0, plate_.cols, plate_.rows);
  const Eigen::Matrix3d H = PlateFromView();
  const cv::Rect target = MapRect(H, roi, all);
  if (target.empty()) return true;
  // This frame's background and matte at each plate pixel of the target.
  const cv::Matx33d M = RectMap(H.inverse(), roi, 1.0, target, 1.0);
  cv::Mat image, matte;
  cv::warpPerspective(image_roi, image, M, target.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar::all(0));
  cv::warpPerspective(matte_roi, matte, M, target.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(1.0));
  const float now = static_cast<float>(now_), max_age = static_cast<float>(options_.max_age_s);
  const float rate = static_cast<float>(options_.update_rate);
  const int outlier = static_cast<int>(options_.outlier_level);
  double diff = 0.0;
  int compared = 0;
  for (int y = 0; y < target.height; ++y) {
    const uchar* in = image.ptr<uchar>(y);
    const float* m = matte.ptr<float>(y);
    uchar* p = plate_.ptr<uchar>(y + target.y) + cn * target.x;
    float* s = seen_.ptr<float>(y + target.y) + target.x;
    for (int x = 0; x < target.width; ++x) {
      if (!(m[x] < background_below)) continue;
      const bool fresh = now - s[x] < max_age;
      int d = 0;
      for (int c = cn * x; c < cn * (x + 1); ++c) d += std::abs(in[c] - p[c]);
      if (fresh) {
        diff += static_cast<double>(d) / cn;
        ++compared;
        // A fresh pixel that disagrees this much is more likely a subject's
        // edge than the scene: not taken; it expires if the scene changed.
        if (d > outlier * cn) continue;
      }
      const float a = fresh ? rate : 1.0f;
      for (int c = cn * x; c < cn * (x + 1); ++c) {
        p[c] = cv::saturate_cast<uchar>(p[c] + a * (in[c] - p[c]));
      }
      s[x] = now;
    }
  }
  if (compared > 400 && diff / compared > options_.scene_cut_level) {
    Reset();
    ++restarts_;
    return false;
  }
  return true;
}

double BackgroundPlate::Coverage() const {
  int fresh = 0;
  const float now = static_cast<float>(now_);
  for (int y = 0; y < seen_.rows; ++y) {
    const float* s = seen_.ptr<float>(y);
    for (int x = 0; x < seen_.cols; ++x) fresh += now - s[x] < options_.max_age_s;
  }
  return static_cast<double>(fresh) / seen_.total();
}

}  // namespace steadiface
