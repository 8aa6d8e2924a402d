#include "steadiface_core/composite/background_plate.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "composite/row_stripes.h"

namespace steadiface {
namespace {

constexpr float kNever = -std::numeric_limits<float>::infinity();

bool In(double v, double lo, double hi) {
  return std::isfinite(v) && v >= lo && v <= hi;
}

}  // namespace

Status ValidateBackgroundPlateOptions(const BackgroundPlateOptions& o) {
  if (!In(o.margin, 0.0, 1.0))
    return Status::Error("composite.plate: margin must be in [0, 1]");
  if (!In(o.max_age_s, 0.01, 60.0)) {
    return Status::Error("composite.plate: max_age_s must be in [0.01, 60] s");
  }
  if (!In(o.update_rate, 0.01, 1.0)) {
    return Status::Error("composite.plate: update_rate must be in [0.01, 1]");
  }
  if (!In(o.reset_angle_deg, 0.1, 90.0)) {
    return Status::Error(
        "composite.plate: reset_angle_deg must be in [0.1, 90] deg");
  }
  if (!In(o.outlier_level, 1.0, 255.0)) {
    return Status::Error("composite.plate: outlier_level must be in [1, 255]");
  }
  if (o.confirm_frames < 1 || o.confirm_frames > 255) {
    return Status::Error("composite.plate: confirm_frames must be in [1, 255]");
  }
  if (!In(o.scene_cut_level, 1.0, 255.0)) {
    return Status::Error(
        "composite.plate: scene_cut_level must be in [1, 255]");
  }
  return Status::Ok();
}

BackgroundPlate::BackgroundPlate(const OutputGeometry& output,
                                 const BackgroundPlateOptions& options)
    : output_(output),
      options_(options),
      margin_x_(static_cast<int>(std::lround(options.margin * output.width()))),
      margin_y_(
          static_cast<int>(std::lround(options.margin * output.height()))) {
  plate_ = cv::Mat(
      output.height() + 2 * margin_y_, output.width() + 2 * margin_x_, CV_8UC3,
      cv::Scalar::all(0));  // retyped on the first image of another type
  seen_ = cv::Mat(plate_.size(), CV_32F, cv::Scalar(kNever));
  agreed_ = cv::Mat::zeros(plate_.size(), CV_8U);
}

void BackgroundPlate::Reset() {
  plate_.setTo(cv::Scalar::all(0));
  seen_.setTo(cv::Scalar(kNever));
  agreed_.setTo(cv::Scalar(0));
  anchored_ = false;
}

bool BackgroundPlate::ViewInside() const {
  const cv::Rect all(0, 0, plate_.cols, plate_.rows);
  const cv::Rect out(0, 0, output_.width(), output_.height());
  const cv::Rect r =
      MapRect(PlateFromView(), out, cv::Rect(-100000, -100000, 200000, 200000));
  return !r.empty() && (r & all) == r;
}

void BackgroundPlate::Begin(const LayerView& view, double time_s) {
  view_ = view;
  now_ = time_s;
  struct Anchor {  // the view-to-plate map, whatever Begin decides below
    BackgroundPlate* p;
    ~Anchor() { p->view_to_plate_ = p->PlateFromView(); }
  } anchor{this};
  if (anchored_) {
    const double angle =
        2.0 * std::acos(std::min(
                  1.0, std::abs((view.R * anchor_.R.conjugate()).w())));
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
  cv::Mat plate, seen, agreed;
  cv::warpPerspective(plate_, plate, M, plate_.size(),
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar::all(0));
  cv::warpPerspective(seen_, seen, M, seen_.size(),
                      cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(kNever));
  cv::warpPerspective(agreed_, agreed, M, agreed_.size(),
                      cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(0));
  plate_ = plate;
  seen_ = seen;
  agreed_ = agreed;
  anchor_ = next;
  ++reprojections_;
}

void BackgroundPlate::Sample(const cv::Rect& roi, cv::Mat* colour,
                             cv::Mat* valid) const {
  Sample(roi, 1.0, colour, valid);
}

void BackgroundPlate::Sample(const cv::Rect& roi, double scale, cv::Mat* colour,
                             cv::Mat* valid) const {
  // (A plate of another type than the images has never been written: it is
  // all unseen, and its colour is not read.)
  const cv::Rect all(0, 0, plate_.cols, plate_.rows);
  const cv::Matx33d M = RectMap(PlateFromView(), all, 1.0, roi, scale);
  const cv::Size size(static_cast<int>(std::lround(roi.width * scale)),
                      static_cast<int>(std::lround(roi.height * scale)));
  cv::warpPerspective(plate_, *colour, M, size,
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar::all(0));
  cv::Mat seen;
  cv::warpPerspective(seen_, seen, M, size,
                      cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(kNever));
  // Fresh: 1 up to 3/4 of the maximum age, fading to 0 at it.
  const float now = static_cast<float>(now_),
              max_age = static_cast<float>(options_.max_age_s);
  valid->create(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    const float* s = seen.ptr<float>(y);
    float* v = valid->ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const float age = now - s[x];
      v[x] =
          std::min(1.0f, std::max(0.0f, (max_age - age) / (0.25f * max_age)));
    }
  }
  // The colour is interpolated from the four nearest plate pixels: next to
  // an unseen one it is not the scene's.
  cv::erode(*valid, *valid, cv::Mat());
}

bool BackgroundPlate::Update(const cv::Mat& image_roi, const cv::Mat& matte_roi,
                             const cv::Rect& roi, float background_below,
                             int row_step, int row_phase) {
  if (image_roi.type() != plate_.type()) {
    plate_ = cv::Mat(plate_.size(), image_roi.type(), cv::Scalar::all(0));
    seen_.setTo(cv::Scalar(kNever));
    agreed_.setTo(cv::Scalar(0));
  }
  const cv::Rect all(0, 0, plate_.cols, plate_.rows);
  const cv::Rect target = MapRect(PlateFromView(), roi, all);
  if (target.empty()) return true;
  // Each plate pixel of the target looks up the view pixel it shows: the
  // matte there (nearest; outside the roi: not taken) and, where it is the
  // scene, the picture (bilinear). Every `row_step`-th row, starting at
  // `row_phase`.
  cv::Mat matte8 = matte_roi;
  if (matte_roi.depth() != CV_8U) matte_roi.convertTo(matte8, CV_8U, 255.0);
  const int below = static_cast<int>(std::ceil(background_below * 255.0f));
  const Eigen::Matrix3d G = HomographyBetween(view_, anchor_);  // view <- plate
  const int step = std::max(1, row_step),
            first = target.y + ((row_phase % step) + step) % step;
  const int rows = (target.y + target.height - first + step - 1) / step;
  double diffs[composite_internal::kRowStripes] = {};
  int counts[composite_internal::kRowStripes] = {};
  composite_internal::ForRowStripes(rows, [&](int k, int i0, int i1) {
    for (int i = i0; i < i1; ++i) {
      UpdateRow(image_roi, matte8, below, G, roi, target.x, first + i * step,
                target.width, &diffs[k], &counts[k]);
    }
  });
  double diff = 0.0;
  int compared = 0;
  for (int k = 0; k < composite_internal::kRowStripes; ++k)
    diff += diffs[k], compared += counts[k];
  if (compared > 400 && diff / compared > options_.scene_cut_level) {
    Reset();
    ++restarts_;
    return false;
  }
  return true;
}

void BackgroundPlate::UpdateRow(const cv::Mat& image, const cv::Mat& matte,
                                int below, const Eigen::Matrix3d& G,
                                const cv::Rect& roi, int x0, int py, int width,
                                double* diff, int* compared) {
  const int cn = plate_.channels();
  uchar* p = plate_.ptr<uchar>(py) + cn * x0;
  float* seen = seen_.ptr<float>(py) + x0;
  uchar* agreed = agreed_.ptr<uchar>(py) + x0;
  const int confirm = options_.confirm_frames;
  const float now = static_cast<float>(now_),
              max_age = static_cast<float>(options_.max_age_s);
  const int outlier = static_cast<int>(options_.outlier_level * cn);
  // The running average's weight of this frame, in 1/256 steps.
  const int rate = static_cast<int>(std::lround(options_.update_rate * 256.0));
  const float w1 = roi.width - 1.0f, h1 = roi.height - 1.0f;
  const Eigen::Vector3d r0 = G * Eigen::Vector3d(x0, py, 1.0) -
                             Eigen::Vector3d(roi.x, roi.y, 0.0) *
                                 (G(2, 0) * x0 + G(2, 1) * py + G(2, 2));
  // (r0 is the view point relative to the roi, homogeneous; each step adds
  // G's first column, less the roi's corner times its z step.)
  const double dx = G(0, 0) - roi.x * G(2, 0), dy = G(1, 0) - roi.y * G(2, 0),
               dz = G(2, 0);
  double X = r0.x(), Y = r0.y(), Z = r0.z();
  // The row's sums in registers (a sum kept through the pointers cost a
  // fifth of the row's time).
  int64_t diff_sum = 0;
  int diff_count = 0;
  for (int x = 0; x < width; ++x, X += dx, Y += dy, Z += dz, p += cn) {
    const float iz = static_cast<float>(1.0 / Z);
    const float vx = static_cast<float>(X) * iz,
                vy = static_cast<float>(Y) * iz;
    if (!(vx >= 0.0f && vy >= 0.0f && vx <= w1 && vy <= h1)) continue;
    if (matte.ptr<uchar>(
            static_cast<int>(vy + 0.5f))[static_cast<int>(vx + 0.5f)] >= below)
      continue;
    const int ix = std::min(static_cast<int>(vx), image.cols - 2);
    const int iy = std::min(static_cast<int>(vy), image.rows - 2);
    const float fx = vx - ix, fy = vy - iy;
    const uchar* a = image.ptr<uchar>(iy) + cn * ix;
    const uchar* b = image.ptr<uchar>(iy + 1) + cn * ix;
    int in[4];
    for (int c = 0; c < cn; ++c) {
      in[c] = static_cast<int>((1 - fy) * ((1 - fx) * a[c] + fx * a[c + cn]) +
                               fy * ((1 - fx) * b[c] + fx * b[c + cn]) + 0.5f);
    }
    const bool fresh = now - seen[x] < max_age;
    int d = 0;
    if (fresh) {
      for (int c = 0; c < cn; ++c) d += std::abs(in[c] - p[c]);
      diff_sum += d;
      ++diff_count;
    }
    if (fresh && d <= outlier) {
      for (int c = 0; c < cn; ++c)
        p[c] = static_cast<uchar>(p[c] + ((rate * (in[c] - p[c]) + 128) >> 8));
      if (agreed[x] < 255) ++agreed[x];
    } else if (fresh && agreed[x] >= confirm) {
      // A confirmed pixel that disagrees this much is more likely a
      // subject's edge than the scene: not taken; it expires if the scene
      // really changed.
      continue;
    } else {
      // New, expired, or an unconfirmed value this frame disagrees with
      // (the value first taken may have been a subject's edge; kept, it
      // would turn the scene away as its outlier until it expired).
      for (int c = 0; c < cn; ++c) p[c] = static_cast<uchar>(in[c]);
      agreed[x] = 1;
    }
    seen[x] = now;
  }
  *diff += static_cast<double>(diff_sum) / cn;
  *compared += diff_count;
}

float BackgroundPlate::SamplePlate(double px, double py, uchar* colour) const {
  // Bilinear; fresh only where all four plate pixels are.
  if (!(px >= 0.0 && py >= 0.0 && px < plate_.cols - 1.0 &&
        py < plate_.rows - 1.0))
    return 0.0f;
  const int x0 = static_cast<int>(px), y0 = static_cast<int>(py);
  const float* s0 = seen_.ptr<float>(y0) + x0;
  const float* s1 = seen_.ptr<float>(y0 + 1) + x0;
  const float oldest = std::min(std::min(s0[0], s0[1]), std::min(s1[0], s1[1]));
  const float max_age = static_cast<float>(options_.max_age_s);
  const float v = std::min(
      1.0f, std::max(0.0f, (max_age - static_cast<float>(now_ - oldest)) /
                               (0.25f * max_age)));
  if (v <= 0.0f) return 0.0f;
  const int cn = plate_.channels();
  const float fx = static_cast<float>(px - x0),
              fy = static_cast<float>(py - y0);
  const uchar* r0 = plate_.ptr<uchar>(y0) + cn * x0;
  const uchar* r1 = plate_.ptr<uchar>(y0 + 1) + cn * x0;
  for (int c = 0; c < cn; ++c) {
    colour[c] = cv::saturate_cast<uchar>(
        (1 - fy) * ((1 - fx) * r0[c] + fx * r0[c + cn]) +
        fy * ((1 - fx) * r1[c] + fx * r1[c + cn]));
  }
  return v;
}

double BackgroundPlate::Coverage() const {
  // On every 4th pixel of every 4th row.
  int fresh = 0, all = 0;
  const float now = static_cast<float>(now_);
  for (int y = 0; y < seen_.rows; y += 4) {
    const float* s = seen_.ptr<float>(y);
    for (int x = 0; x < seen_.cols; x += 4, ++all)
      fresh += now - s[x] < options_.max_age_s;
  }
  return all > 0 ? static_cast<double>(fresh) / all : 0.0;
}

}  // namespace steadiface
