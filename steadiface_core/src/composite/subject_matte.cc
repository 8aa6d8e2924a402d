#include "steadiface_core/composite/subject_matte.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/common/grey.h"
#include "steadiface_core/composite/guided_filter.h"
#include "composite/row_stripes.h"

namespace steadiface {
namespace {

constexpr int kLevels = 8;  // colour histogram levels per channel

bool In(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

float Clamp(float v, float lo, float hi) { return std::min(hi, std::max(lo, v)); }

// `in` averaged over s x s blocks into `size` (INTER_AREA). A power of two
// halves it step by step: OpenCV vectorizes the halving, not the larger
// factors (a 720p colour frame to 1/4: 0.65 ms in one step, 0.20 ms in two
// halvings; each halving rounds, so they differ by at most a grey level).
void DownscaleArea(const cv::Mat& in, int s, const cv::Size& size, cv::Mat* out) {
  if (s < 2 || (s & (s - 1)) != 0) {
    cv::resize(in, *out, size, 0, 0, cv::INTER_AREA);
    return;
  }
  cv::Mat level = in;
  for (int k = s; k > 1; k /= 2) {
    cv::Mat half;
    const cv::Size next = k == 2 ? size : cv::Size((level.cols + 1) / 2, (level.rows + 1) / 2);
    cv::resize(level, half, next, 0, 0, cv::INTER_AREA);
    level = half;
  }
  *out = level;
}


int Bin(const uchar* px, int cn) {
  if (cn == 1) return px[0] * kLevels / 256;
  return ((px[0] * kLevels / 256) * kLevels + px[1] * kLevels / 256) * kLevels +
         px[2] * kLevels / 256;
}

// The log-odds prior of the landmarks: the region's outline (at signed
// distance sd) softened, and certain inside the face (the landmarks' own
// oval).
float PriorLogOdds(const SubjectRegion& r, const Eigen::Vector2d& p, double sd, double softness) {
  const double jaw = std::max(1.0, r.jaw_width);
  float l = Clamp(static_cast<float>(-sd / (softness * jaw)), -3.0f, 3.0f);
  const Eigen::Vector2d c = std::isfinite(r.face_centre.x()) ? r.face_centre : r.head_centre;
  const Eigen::Vector2d q((p.x() - c.x()) / (0.42 * jaw),
                          (p.y() - c.y()) / std::max(1.0, 0.55 * r.face_height));
  if (q.squaredNorm() < 1.0) l = std::max(l, 4.0f);
  return l;
}

}  // namespace

Status ValidateSubjectMatteOptions(const SubjectMatteOptions& o) {
  if (o.scale < 1 || o.scale > 16) return Status::Error("composite.matte: scale must be in [1, 16]");
  if (!In(o.search_jaw_widths, 0.0, 5.0) || !In(o.prior_softness, 0.01, 5.0)) {
    return Status::Error(
        "composite.matte: search_jaw_widths must be in [0, 5] and prior_softness in [0.01, 5]");
  }
  if (!In(o.plate_level, 1.0, 255.0) || !In(o.motion_level, 1.0, 255.0)) {
    return Status::Error("composite.matte: plate_level and motion_level must be in [1, 255]");
  }
  if (!In(o.plate_confidence, 0.0, 8.0)) {
    return Status::Error("composite.matte: plate_confidence must be in [0, 8]");
  }
  if (o.absent_frames < 0 || o.absent_frames > 255) {
    return Status::Error("composite.matte: absent_frames must be in [0, 255]");
  }
  if (!In(o.motion_memory, 0.0, 0.99)) {
    return Status::Error("composite.matte: motion_memory must be in [0, 0.99]");
  }
  if (!In(o.colour_weight, 0.0, 10.0) || !In(o.temporal, 0.0, 0.95)) {
    return Status::Error(
        "composite.matte: colour_weight must be in [0, 10] and temporal in [0, 0.95]");
  }
  if (o.edge_radius_px < 0 || o.edge_radius_px > 64 || !In(o.edge_eps, 1e-6, 1.0)) {
    return Status::Error(
        "composite.matte: edge_radius_px must be in [0, 64] and edge_eps in [1e-6, 1]");
  }
  return Status::Ok();
}

struct SubjectMatte::LowRes {
  int s = 1;
  cv::Rect roi;              // low-resolution pixels
  // roi in output pixels (its low pixels' full extent).
  cv::Rect ViewRoi() const { return cv::Rect(roi.x * s, roi.y * s, roi.width * s, roi.height * s); }
  cv::Mat background;        // whole output, grey, low resolution
  cv::Mat subject;           // whole output, grey, low resolution
  cv::Mat colour;            // the background layer over roi, low resolution
  cv::Mat plate, plate_valid;  // over roi, low resolution (empty: none)
};

SubjectMatte::SubjectMatte(const SubjectMatteOptions& options)
    : options_(options),
      subject_hist_(kLevels * kLevels * kLevels, 0.0f),
      scene_hist_(kLevels * kLevels * kLevels, 0.0f) {}

void SubjectMatte::Reset() {
  has_previous_ = false;
  accumulated_.release();
  absent_.release();
  std::fill(subject_hist_.begin(), subject_hist_.end(), 0.0f);
  std::fill(scene_hist_.begin(), scene_hist_.end(), 0.0f);
}

cv::Rect SubjectMatte::Roi(const SubjectRegion& r, const cv::Size& output) const {
  if (!r.valid || !(r.jaw_width > 1.0) || !(r.blend > 0.0)) return cv::Rect();
  const double grow = options_.search_jaw_widths * r.jaw_width;
  double x0 = r.head_centre.x() - r.head_axes.x(), x1 = r.head_centre.x() + r.head_axes.x();
  double y0 = r.head_centre.y() - r.head_axes.y(), y1 = r.head_centre.y() + r.head_axes.y();
  if (r.torso) {
    x0 = std::min(x0, r.shoulder_centre.x() - r.shoulder_axes.x());
    x1 = std::max(x1, r.shoulder_centre.x() + r.shoulder_axes.x());
    y1 = std::max(y1, r.shoulder_centre.y() + r.shoulder_axes.y());
  }
  if (!std::isfinite(x0 + x1 + y0 + y1)) return cv::Rect();
  const int s = options_.scale;
  auto down = [&](double v) {
    return static_cast<int>(std::floor(std::max(-1e6, std::min(1e6, v)) / s)) * s;
  };
  const int ix0 = down(x0 - grow), iy0 = down(y0 - grow);
  const int ix1 = down(x1 + grow) + s, iy1 = down(y1 + grow) + s;
  return cv::Rect(ix0, iy0, ix1 - ix0, iy1 - iy0) & cv::Rect(0, 0, output.width, output.height);
}

void SubjectMatte::Estimate(const MatteInputs& in, cv::Rect* active, cv::Mat* matte) {
  const int s = options_.scale;
  LowRes low;
  low.s = s;
  const cv::Size small((in.background.cols + s - 1) / s, (in.background.rows + s - 1) / s);
  cv::Mat bg_small, subject_small;
  DownscaleArea(in.background, s, small, &bg_small);
  low.background = ToGrey(bg_small);
  DownscaleArea(in.subject, s, small, &subject_small);
  low.subject = ToGrey(subject_small);
  low.roi = LowRoi(in.roi, small);
  low.colour = bg_small(low.roi);
  low.plate = in.plate;
  low.plate_valid = in.plate_valid;
  cv::Mat logodds, verified;
  const cv::Mat lm = MotionEvidence(in, low);
  const cv::Mat accumulated = AccumulateMotion(in, low, lm);
  Evidence(in, low, lm, accumulated, &logodds, &verified);
  VerifyLongAbsent(in, low, logodds, &verified);
  Refine(in, low, logodds, active, matte);
  scene_known_low_ = verified;
  low_roi_ = low.roi;
  Remember(in, logodds, low, verified);
}

cv::Rect SubjectMatte::LowRoi(const cv::Rect& roi, const cv::Size& small) const {
  const int s = options_.scale;
  return cv::Rect(roi.x / s, roi.y / s, (roi.width + s - 1) / s, (roi.height + s - 1) / s) &
         cv::Rect(0, 0, small.width, small.height);
}

void SubjectMatte::Refine(const MatteInputs& in, const LowRes& low, const cv::Mat& logodds,
                          cv::Rect* active, cv::Mat* matte) const {
  // Low-resolution matte, refined at the picture's edges (He and Sun's fast
  // guided filter: the linear coefficients at low resolution, applied to the
  // full-resolution guide) where the subject may be: the low matte's
  // support, grown by the filter's reach.
  const int s = low.s;
  cv::Mat p(logodds.size(), CV_32F);
  int x0 = p.cols, y0 = p.rows, x1 = -1, y1 = -1;
  for (int y = 0; y < p.rows; ++y) {
    const float* l = logodds.ptr<float>(y);
    float* m = p.ptr<float>(y);
    for (int x = 0; x < p.cols; ++x) {
      // Confident pixels are exactly 0 or 1, so the filter's coefficient a
      // vanishes away from the edges (and the per-pixel refinement with it).
      m[x] = l[x] >= 4.0f ? 1.0f : l[x] <= -4.0f ? 0.0f : 1.0f / (1.0f + std::exp(-l[x]));
      if (m[x] > 0.01f) {
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
  }
  *active = cv::Rect();
  matte->release();
  if (x1 < 0) return;
  const int r = std::max(1, options_.edge_radius_px / s);
  cv::Mat guide_low, mean_a, mean_b;
  low.background(low.roi).convertTo(guide_low, CV_32F, 1.0 / 255.0);
  GuidedFilterCoefficients(guide_low, p, r, options_.edge_eps, &mean_a, &mean_b);
  // The active rectangle in low pixels (of the roi), then in output pixels.
  const cv::Rect low_active =
      cv::Rect(x0 - 2 * r - 1, y0 - 2 * r - 1, x1 - x0 + 4 * r + 3, y1 - y0 + 4 * r + 3) &
      cv::Rect(0, 0, p.cols, p.rows);
  *active = cv::Rect((low.roi.x + low_active.x) * s, (low.roi.y + low_active.y) * s,
                     low_active.width * s, low_active.height * s) &
            in.roi;
  if (active->empty()) return;
  // Where the coefficient a is small the guide's detail does not show: the
  // low-resolution output, interpolated. Elsewhere (the edges) a I + b per
  // pixel, with a and b interpolated.
  cv::Mat q_low = mean_a.mul(guide_low) + mean_b;
  cv::min(q_low, 1.0, q_low);
  cv::max(q_low, 0.0, q_low);
  cv::Mat base;
  const cv::Size up(low_active.width * s, low_active.height * s);
  cv::resize(q_low(low_active), base, up, 0, 0, cv::INTER_LINEAR);
  const cv::Rect crop(active->x - (low.roi.x + low_active.x) * s,
                      active->y - (low.roi.y + low_active.y) * s, active->width, active->height);
  *matte = base(crop);
  cv::Mat edge = cv::abs(mean_a) > 0.02;
  cv::dilate(edge, edge, cv::Mat());
  RefineEdges(in.background, low.roi, *active, mean_a, mean_b, edge, matte);
}

void SubjectMatte::RefineEdges(const cv::Mat& picture, const cv::Rect& low_roi,
                               const cv::Rect& active, const cv::Mat& mean_a,
                               const cv::Mat& mean_b, const cv::Mat& edge, cv::Mat* matte) const {
  // a I + b at full resolution in the low cells marked `edge`, a and b
  // interpolated bilinearly between the low pixels' centres, clamped to
  // [0, 1]; other cells keep the interpolated low-resolution output. Each
  // row interpolates a and b between two low rows first.
  const int s = options_.scale, cn = picture.channels();
  const float inv = 1.0f / s;
  std::vector<int> u0(active.width);
  std::vector<float> fu(active.width);
  for (int i = 0; i < active.width; ++i) {
    const float u = (active.x + i + 0.5f) * inv - 0.5f - low_roi.x;
    u0[i] = std::max(0, std::min(mean_a.cols - 2, static_cast<int>(std::floor(u))));
    fu[i] = std::min(1.0f, std::max(0.0f, u - u0[i]));
  }
  composite_internal::ForRowStripes(active.height, [&](int, int y0, int y1) {
    std::vector<float> a_row(mean_a.cols), b_row(mean_a.cols);
    for (int Y = active.y + y0; Y < active.y + y1; ++Y) {
      const int cy = Y / s - low_roi.y;
      if (cy < 0 || cy >= edge.rows) continue;
      const uchar* e = edge.ptr<uchar>(cy);
      bool any = false;
      for (int cx = 0; cx < edge.cols && !any; ++cx) any = e[cx] != 0;
      if (!any) continue;
      const float v = (Y + 0.5f) * inv - 0.5f - low_roi.y;
      const int v0 = std::max(0, std::min(mean_a.rows - 2, static_cast<int>(std::floor(v))));
      const float fv = std::min(1.0f, std::max(0.0f, v - v0));
      for (int u = 0; u < mean_a.cols; ++u) {
        a_row[u] = (1 - fv) * mean_a.at<float>(v0, u) + fv * mean_a.at<float>(v0 + 1, u);
        b_row[u] = (1 - fv) * mean_b.at<float>(v0, u) + fv * mean_b.at<float>(v0 + 1, u);
      }
      const uchar* px = picture.ptr<uchar>(Y);
      float* m = matte->ptr<float>(Y - active.y);
      for (int i = 0; i < active.width; ++i) {
        const int X = active.x + i, cx = X / s - low_roi.x;
        if (cx < 0 || cx >= edge.cols || !e[cx]) continue;
        const uchar* c = px + cn * X;
        const float I = cn >= 3 ? (0.114f * c[0] + 0.587f * c[1] + 0.299f * c[2]) / 255.0f
                                : c[0] / 255.0f;
        const int k = u0[i];
        const float f = fu[i];
        const float a = (1 - f) * a_row[k] + f * a_row[k + 1];
        const float b = (1 - f) * b_row[k] + f * b_row[k + 1];
        m[i] = std::min(1.0f, std::max(0.0f, a * I + b));
      }
    }
  });
}

cv::Mat SubjectMatte::MotionEvidence(const MatteInputs& in, const LowRes& low) const {
  // Each layer's change since the last frame at this frame's background
  // pixels: the scene stands still in the background layer, the subject in
  // the subject layer. NaN where unknown.
  const int s = low.s;
  const cv::Rect& rl = low.roi;
  cv::Mat lm(rl.size(), CV_32F, cv::Scalar(NAN));
  if (!has_previous_) return lm;
  const cv::Rect whole(0, 0, in.background.cols, in.background.rows);
  const cv::Rect view_rl = low.ViewRoi();
  const cv::Matx33d Mb = RectMap(HomographyBetween(previous_view_, in.background_view), whole,
                                 1.0 / s, view_rl, 1.0 / s);
  cv::Mat prev_bg, moved_bg, subject_change, moved_subject;
  previous_background_.convertTo(prev_bg, CV_32F);
  cv::warpPerspective(prev_bg, moved_bg, Mb, rl.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(-1));
  cv::absdiff(low.subject, previous_subject_, subject_change);
  subject_change.convertTo(subject_change, CV_32F);
  const cv::Matx33d Ms = RectMap(HomographyBetween(in.subject_view, in.background_view), whole,
                                 1.0 / s, view_rl, 1.0 / s);
  cv::warpPerspective(subject_change, moved_subject, Ms, rl.size(),
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT, cv::Scalar(-1));
  const float level = static_cast<float>(options_.motion_level);
  for (int y = 0; y < rl.height; ++y) {
    const uchar* bg = low.background.ptr<uchar>(y + rl.y) + rl.x;
    const float* eb = moved_bg.ptr<float>(y);
    const float* es = moved_subject.ptr<float>(y);
    float* l = lm.ptr<float>(y);
    for (int x = 0; x < rl.width; ++x) {
      if (eb[x] >= 0.0f && es[x] >= 0.0f) {
        l[x] = Clamp((std::abs(bg[x] - eb[x]) - es[x]) / level, -2.5f, 2.5f);
      }
    }
  }
  return lm;
}

cv::Mat SubjectMatte::AccumulateMotion(const MatteInputs& in, const LowRes& low,
                                       const cv::Mat& lm) {
  // The motion evidence summed over time where the subject stands still: in
  // the subject layer's view, decaying by motion_memory per frame.
  const int s = low.s;
  const cv::Rect& rl = low.roi;
  const cv::Size small = low.subject.size();
  const cv::Rect whole(0, 0, in.background.cols, in.background.rows);
  const cv::Rect view_rl = low.ViewRoi();
  if (accumulated_.size() != small) accumulated_ = cv::Mat::zeros(small, CV_32F);
  accumulated_ *= options_.motion_memory;
  cv::Mat moved;
  cv::warpPerspective(lm, moved,
                      RectMap(HomographyBetween(in.background_view, in.subject_view), view_rl,
                              1.0 / s, whole, 1.0 / s),
                      small, cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                      cv::Scalar(NAN));
  for (int y = 0; y < small.height; ++y) {
    const float* m = moved.ptr<float>(y);
    float* a = accumulated_.ptr<float>(y);
    for (int x = 0; x < small.width; ++x) {
      if (std::isfinite(m[x])) a[x] += m[x];
    }
  }
  cv::Mat back;
  cv::warpPerspective(accumulated_, back,
                      RectMap(HomographyBetween(in.subject_view, in.background_view), whole,
                              1.0 / s, view_rl, 1.0 / s),
                      rl.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                      cv::Scalar(0));
  return back;
}

void SubjectMatte::Evidence(const MatteInputs& in, const LowRes& low, const cv::Mat& lm,
                            const cv::Mat& accumulated, cv::Mat* logodds,
                            cv::Mat* verified) const {
  const SubjectMatteOptions& o = options_;
  const int s = low.s;
  const cv::Rect& rl = low.roi;
  const Eigen::Vector2d shift = (in.region.head_centre - previous_head_) / s;
  const int cn = low.colour.channels();
  const bool plate = !low.plate.empty();
  const double search = o.search_jaw_widths * std::max(1.0, in.region.jaw_width);
  logodds->create(rl.size(), CV_32F);
  verified->create(rl.size(), CV_32F);
  composite_internal::ForRowStripes(rl.height, [&](int, int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      float* L = logodds->ptr<float>(y);
      float* V = verified->ptr<float>(y);
      const uchar* col = low.colour.ptr<uchar>(y);
      for (int x = 0; x < rl.width; ++x) {
        const Eigen::Vector2d p((rl.x + x + 0.5) * s - 0.5, (rl.y + y + 0.5) * s - 0.5);
        V[x] = 1.0f;
        const double sd = in.region.SignedDistance(p);
        if (sd > search) {
          L[x] = -8.0f;
          continue;
        }
        const float prior = PriorLogOdds(in.region, p, sd, o.prior_softness);
        float l = prior;
        if (plate) {
          const uchar* pl = low.plate.ptr<uchar>(y) + cn * x;
          float d = 0.0f;
          for (int c = 0; c < cn; ++c) d += std::abs(col[cn * x + c] - pl[c]);
          d /= cn;
          const float v = low.plate_valid.at<float>(y, x);
          const float level = static_cast<float>(o.plate_level);
          l += v * Clamp((d - level) / (0.5f * level), -3.0f, 3.0f);
        }
        const float acc = accumulated.at<float>(y, x), now = lm.at<float>(y, x);
        l += Clamp(acc, -4.0f, 4.0f);
        if (has_previous_) {
          const int px = static_cast<int>(std::lround(rl.x + x - shift.x())) - previous_low_roi_.x;
          const int py = static_cast<int>(std::lround(rl.y + y - shift.y())) - previous_low_roi_.y;
          if (px >= 0 && py >= 0 && px < previous_logodds_.cols && py < previous_logodds_.rows) {
            l += static_cast<float>(o.temporal) * previous_logodds_.at<float>(py, px);
          }
        }
        l += static_cast<float>(o.colour_weight) * ColourLogRatio(col + cn * x, cn);
        L[x] = Clamp(l, -8.0f, 8.0f);
        // The plate (and the colour model's scene) may take a pixel only where
        // the scene is known to be there: beyond the search, or seen standing
        // still in the background layer while it moved in the subject layer,
        // now and over the recent frames. A subject pixel the matte missed must
        // not enter the plate, or the plate would then call it scene; the
        // landmarks' region alone is no proof, a subject may reach beyond it.
        // Or, where nothing moves (a plain wall), outside the landmarks'
        // region and confidently the scene by all the evidence together.
        const bool moved_as_scene = std::isfinite(now) && now <= -1.0f && acc <= -1.0f;
        const bool confident = prior <= -1.0f && L[x] <= -static_cast<float>(o.plate_confidence);
        V[x] = moved_as_scene || confident ? 1.0f : 0.0f;
      }
    }
  });
}

void SubjectMatte::VerifyLongAbsent(const MatteInputs& in, const LowRes& low,
                                    const cv::Mat& logodds, cv::Mat* verified) {
  // The subject stands still in the subject layer's view. There, a spot the
  // matte has not put the subject on for absent_frames frames in a row is
  // the scene, even where nothing textured moved to prove it. Present: the
  // matte above 0.018 (log-odds -4), grown by a low pixel; absent: below,
  // and beyond the roi; unknown (128): outside this frame's view.
  if (options_.absent_frames <= 0) return;
  const int s = low.s;
  const cv::Rect& rl = low.roi;
  const cv::Size small = low.subject.size();
  const cv::Rect whole(0, 0, in.background.cols, in.background.rows);
  const cv::Rect view_rl = low.ViewRoi();
  cv::Mat present = cv::Mat::zeros(small, CV_8U);
  present(rl).setTo(cv::Scalar(255), logodds > -4.0f);
  cv::dilate(present, present, cv::Mat());
  cv::Mat moved;
  cv::warpPerspective(present, moved,
                      RectMap(HomographyBetween(in.background_view, in.subject_view), whole,
                              1.0 / s, whole, 1.0 / s),
                      small, cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                      cv::Scalar(128));
  if (absent_.size() != small) absent_ = cv::Mat::zeros(small, CV_8U);
  for (int y = 0; y < small.height; ++y) {
    const uchar* m = moved.ptr<uchar>(y);
    uchar* a = absent_.ptr<uchar>(y);
    for (int x = 0; x < small.width; ++x) {
      if (m[x] == 255) {
        a[x] = 0;
      } else if (m[x] == 0 && a[x] < 255) {
        ++a[x];
      }
    }
  }
  cv::Mat back;
  cv::warpPerspective(absent_, back,
                      RectMap(HomographyBetween(in.subject_view, in.background_view), whole,
                              1.0 / s, view_rl, 1.0 / s),
                      rl.size(), cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                      cv::Scalar(0));
  verified->setTo(cv::Scalar(1.0f), back >= options_.absent_frames);
}

float SubjectMatte::ColourLogRatio(const uchar* px, int cn) const {
  const int b = Bin(px, cn);
  const float fg = subject_hist_[b], bg = scene_hist_[b];
  if (fg + bg < 1.0f) return 0.0f;  // colour never seen with confidence
  return Clamp(std::log((fg + 0.5f) / (bg + 0.5f)), -2.0f, 2.0f);
}

void SubjectMatte::Remember(const MatteInputs& in, const cv::Mat& logodds, const LowRes& low,
                            const cv::Mat& verified) {
  // The colour model learns, forgetting slowly, the subject from confident
  // pixels and the scene only where the scene is known (outside the region,
  // or seen standing still in the background layer): a subject pixel the
  // matte missed must not teach the scene's colours.
  for (float& h : subject_hist_) h *= 0.9f;
  for (float& h : scene_hist_) h *= 0.9f;
  const int cn = low.colour.channels();
  for (int y = 0; y < logodds.rows; ++y) {
    const float* L = logodds.ptr<float>(y);
    const float* V = verified.ptr<float>(y);
    const uchar* col = low.colour.ptr<uchar>(y);
    for (int x = 0; x < logodds.cols; ++x) {
      if (L[x] > 3.0f) subject_hist_[Bin(col + cn * x, cn)] += 1.0f;
      if (V[x] > 0.5f && L[x] < 0.0f && L[x] > -7.9f) scene_hist_[Bin(col + cn * x, cn)] += 1.0f;
    }
  }
  has_previous_ = true;
  previous_background_ = low.background;
  previous_subject_ = low.subject;
  previous_view_ = in.background_view;
  previous_logodds_ = logodds;
  previous_low_roi_ = low.roi;
  previous_head_ = in.region.head_centre;
}

}  // namespace steadiface
