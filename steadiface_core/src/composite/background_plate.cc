#include "steadiface_core/composite/background_plate.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "composite/row_stripes.h"
#include "steadiface_core/warp/mesh_sampler.h"
#include "steadiface_core/warp/warper.h"

namespace steadiface {
namespace {

constexpr float kNever = -std::numeric_limits<float>::infinity();

bool In(double v, double lo, double hi) {
  return std::isfinite(v) && v >= lo && v <= hi;
}

// The view-point mesh's largest departure from the homography it stands
// for, well below the sampler's 1/32 px [px].
constexpr double kViewMeshError = 0.01;

// The view point of plate pixel (x, y): G maps plate to view pixels.
Eigen::Vector2d ViewPoint(const Eigen::Matrix3d& G, double x, double y) {
  const Eigen::Vector3d q = G * Eigen::Vector3d(x, y, 1.0);
  return q.head<2>() / q.z();
}

// The side of the view-point mesh's cells over plate rectangle `target`
// (rows `step` apart): the interpolation error grows with the side squared,
// so it is measured for 64 px cells at the target's corners and edge
// midpoints (where the homography bends most) and the side scaled to
// kViewMeshError; a power of two in [4, 128] [px].
int ViewMeshCell(const Eigen::Matrix3d& G, const cv::Rect& target, int step) {
  const double L = 64.0;
  double error = 0.0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double x = target.x + i * std::max(0.0, target.width - L) / 2.0;
      const double y =
          target.y + j * std::max(0.0, target.height - L * step) / 2.0;
      const Eigen::Vector2d mid =
          (ViewPoint(G, x, y) + ViewPoint(G, x + L, y) +
           ViewPoint(G, x, y + L * step) + ViewPoint(G, x + L, y + L * step)) /
          4.0;
      const Eigen::Vector2d truth =
          ViewPoint(G, x + L / 2.0, y + L * step / 2.0);
      if (mid.allFinite() && truth.allFinite())
        error = std::max(error, (mid - truth).lpNorm<Eigen::Infinity>());
    }
  }
  int cell = 128;
  while (cell > 4 && error * (cell / L) * (cell / L) > kViewMeshError)
    cell /= 2;
  return cell;
}

// The view points (relative to `roi`) of plate rows y0, y0 + step, ... (`rows`
// of them) from column x0, `width` wide, as a warp mesh: output pixel (u, v)
// is plate pixel (x0 + u, y0 + v step), and G maps plate to view pixels.
WarpMesh ViewPointMesh(const Eigen::Matrix3d& G, const cv::Rect& roi, int x0,
                       int y0, int step, int width, int rows, int cell) {
  WarpMesh m;
  const auto nodes = [cell](int n) {
    std::vector<double> at;
    for (int i = 0; i < n - 1; i += cell) at.push_back(i);
    at.push_back(std::max(0, n - 1));
    if (at.size() < 2) at.push_back(at.back() + 1.0);
    return at;
  };
  m.u = nodes(width);
  m.v = nodes(rows);
  m.cols = static_cast<int>(m.u.size());
  m.rows = static_cast<int>(m.v.size());
  for (double v : m.v) {
    for (double u : m.u) {
      const Eigen::Vector2d q =
          ViewPoint(G, x0 + u, y0 + v * step) - Eigen::Vector2d(roi.x, roi.y);
      m.source.push_back(q.cast<float>());
      m.source_row.push_back(m.source.back().y());
    }
  }
  return m;
}

// Whether each of `width` plate pixels of row py from x0 is taken: its view
// pixel (G maps plate to view pixels) is inside output rectangle `roi` and
// `matte` (1/255 steps, over `roi`) is below `below` there (nearest; the
// view point exact every `cell` pixels, linear between).
void SceneInView(const cv::Mat& matte, int below, const Eigen::Matrix3d& G,
                 const cv::Rect& roi, int x0, int py, int width, int cell,
                 uchar* take) {
  // The view point is exact at every `cell`-th pixel and stepped linearly
  // between (as the picture's mesh is); each stretch starts where the one
  // before it ended.
  const float w1 = roi.width - 1.0f, h1 = roi.height - 1.0f;
  const Eigen::Vector2d corner(roi.x, roi.y);
  Eigen::Vector2f a = (ViewPoint(G, x0, py) - corner).cast<float>();
  for (int u0 = 0; u0 < width; u0 += cell) {
    const int n = std::min(cell, width - u0);
    const Eigen::Vector2f b =
        (ViewPoint(G, x0 + u0 + n, py) - corner).cast<float>();
    float vx = a.x(), vy = a.y();
    const float dx = (b.x() - vx) / n, dy = (b.y() - vy) / n;
    for (int u = u0; u < u0 + n; ++u, vx += dx, vy += dy) {
      take[u] = vx >= 0.0f && vy >= 0.0f && vx <= w1 && vy <= h1 &&
                matte.ptr<uchar>(static_cast<int>(
                    vy + 0.5f))[static_cast<int>(vx + 0.5f)] < below;
    }
    a = b;
  }
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
  // matte there (nearest; outside the roi: not taken) and the picture
  // (bilinear, through a mesh of the view points). Every `row_step`-th row,
  // starting at `row_phase`.
  cv::Mat matte8 = matte_roi;
  if (matte_roi.depth() != CV_8U) matte_roi.convertTo(matte8, CV_8U, 255.0);
  const int below = static_cast<int>(std::ceil(background_below * 255.0f));
  const Eigen::Matrix3d G = HomographyBetween(view_, anchor_);  // view <- plate
  const int step = std::max(1, row_step),
            first = target.y + ((row_phase % step) + step) % step;
  const int rows = (target.y + target.height - first + step - 1) / step;
  if (rows <= 0) return true;
  const int cell = ViewMeshCell(G, target, step);
  SampleMesh(
      ViewPointMesh(G, roi, target.x, first, step, target.width, rows, cell),
      image_roi, target.width, rows, &in_);
  double diffs[composite_internal::kRowStripes] = {};
  int counts[composite_internal::kRowStripes] = {};
  composite_internal::ForRowStripes(rows, [&](int k, int i0, int i1) {
    std::vector<uchar> take(target.width);
    for (int i = i0; i < i1; ++i) {
      const int py = first + i * step;
      SceneInView(matte8, below, G, roi, target.x, py, target.width, cell,
                  take.data());
      UpdateRow(in_.ptr<uchar>(i), take.data(), target.x, py, target.width,
                &diffs[k], &counts[k]);
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

void BackgroundPlate::UpdateRow(const uchar* in, const uchar* take, int x0,
                                int py, int width, double* diff,
                                int* compared) {
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
  // The row's sums in registers (a sum kept through the pointers cost a
  // fifth of the row's time).
  int64_t diff_sum = 0;
  int diff_count = 0;
  for (int x = 0; x < width; ++x, p += cn, in += cn) {
    if (!take[x]) continue;
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
      for (int c = 0; c < cn; ++c) p[c] = in[c];
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
