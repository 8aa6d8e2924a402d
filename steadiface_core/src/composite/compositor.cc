#include "steadiface_core/composite/compositor.h"

#include <chrono>

#include <opencv2/imgproc.hpp>

#include "composite/row_stripes.h"
#include "steadiface_core/common/stopwatch.h"

namespace steadiface {
namespace {

// A fill that shows through the subject by less than this is not made.
constexpr float kFillNone = 1.0f / 64.0f;

}  // namespace

Status ValidateCompositeOptions(const CompositeOptions& o) {
  Status s = ValidateSubjectMatteOptions(o.matte);
  if (!s.ok()) return s;
  s = ValidateBackgroundPlateOptions(o.plate);
  if (!s.ok()) return s;
  if (!(o.plate_below >= 0.0 && o.plate_below <= 1.0)) {
    return Status::Error("composite: plate_below must be in [0, 1]");
  }
  if (o.plate_row_step < 1 || o.plate_row_step > 8) {
    return Status::Error("composite: plate_row_step must be in [1, 8]");
  }
  if (o.plate_distance_px < 0 || o.plate_distance_px > 64) {
    return Status::Error("composite: plate_distance_px must be in [0, 64]");
  }
  return Status::Ok();
}

Compositor::Compositor(const OutputGeometry& output, const CompositeOptions& options)
    : output_(output), options_(options), matte_(options.matte), plate_(output, options.plate) {}

Status Compositor::Create(const OutputGeometry& output, const CompositeOptions& options,
                          std::unique_ptr<Compositor>* out) {
  const Status s = ValidateCompositeOptions(options);
  if (!s.ok()) return s;
  out->reset(new Compositor(output, options));
  return Status::Ok();
}

void Compositor::Reset() {
  matte_.Reset();
  plate_.Reset();
  past_rois_.clear();
  report_ = CompositeReport();
}

Status Compositor::Compose(const cv::Mat& subject, const LayerView& subject_view,
                           const cv::Mat& background, const LayerView& background_view,
                           const SubjectRegion& region, double time_s, cv::Mat* out) {
  if (subject.empty() || subject.size() != background.size() ||
      subject.type() != background.type() || subject.depth() != CV_8U ||
      subject.cols != output_.width() || subject.rows != output_.height()) {
    return Status::Error("composite: the layers' pictures must be 8-bit, of one type, output-sized");
  }
  report_ = CompositeReport();
  if (out->data != background.data) background.copyTo(*out);
  plate_.Begin(background_view, time_s);
  const cv::Size size = background.size();
  const cv::Rect roi = matte_.Roi(region, size);
  report_.plate_restarts = plate_.restarts();
  report_.plate_reprojections = plate_.reprojections();
  matte_b_.release();
  matte_b8_.release();
  matte_s_.release();
  plate_weight_.release();
  plate_sample_.release();
  if (roi.empty()) return Status::Ok();
  auto t0 = std::chrono::steady_clock::now();
  MatteInputs in;
  in.background = background;
  in.subject = subject;
  in.background_view = background_view;
  in.subject_view = subject_view;
  in.region = region;
  in.roi = roi;
  // The plate at the matte's low resolution.
  const int s = matte_.scale();
  const cv::Rect rl = matte_.LowRoi(roi, cv::Size((size.width + s - 1) / s, (size.height + s - 1) / s));
  const cv::Rect view_rl(rl.x * s, rl.y * s, rl.width * s, rl.height * s);
  plate_.Sample(view_rl, 1.0 / s, &in.plate, &in.plate_valid);
  report_.plate_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();
  cv::Rect active;
  cv::Mat raw;
  matte_.Estimate(in, &active, &raw);
  report_.matte_ms = MsSince(t0);
  if (!active.empty()) ComposeActive(subject, subject_view, background_view, region, active, raw, out);
  t0 = std::chrono::steady_clock::now();
  report_.plate_learnt = LearnRect(background_view, roi, time_s);
  UpdatePlate(background, report_.plate_learnt, active, raw);
  report_.plate_ms += MsSince(t0);
  report_.plate_coverage = plate_.Coverage();
  report_.plate_restarts = plate_.restarts();
  report_.plate_reprojections = plate_.reprojections();
  return Status::Ok();
}

void Compositor::ComposeActive(const cv::Mat& subject, const LayerView& subject_view,
                               const LayerView& background_view, const SubjectRegion& region,
                               const cv::Rect& active, const cv::Mat& raw, cv::Mat* out) {
  auto t0 = std::chrono::steady_clock::now();
  report_.active = true;
  report_.background_roi = active;
  // (A copy when scaled: `raw`, unscaled, keeps the subject out of the plate.)
  matte_b_ = region.blend < 1.0 ? cv::Mat(raw * region.blend) : raw;
  matte_b_.convertTo(matte_b8_, CV_8U, 255.0);
  // The matte in the subject layer's view (in 1/255 steps, as it is blended).
  const cv::Rect whole(0, 0, out->cols, out->rows);
  const Eigen::Matrix3d H_sb = HomographyBetween(subject_view, background_view);
  const Eigen::Matrix3d H_bs = HomographyBetween(background_view, subject_view);
  const cv::Rect roi_s = MapRect(H_sb, active, whole);
  report_.subject_roi = roi_s;
  if (!roi_s.empty()) {
    cv::warpPerspective(matte_b8_, matte_s_, RectMap(H_bs, active, 1.0, roi_s, 1.0), roi_s.size(),
                        cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                        cv::Scalar(0));
  }
  report_.matte_ms += MsSince(t0);
  t0 = std::chrono::steady_clock::now();
  FillUncovered(subject, out);
  if (!roi_s.empty()) Blend(subject, out);
  report_.blend_ms = MsSince(t0);
}

cv::Rect Compositor::LearnRect(const LayerView& view, const cv::Rect& roi, double time_s) {
  const double max_age = options_.plate.max_age_s;
  if (!past_rois_.empty() && past_rois_.back().time_s > time_s) past_rois_.clear();  // time went back
  while (!past_rois_.empty() &&
         (past_rois_.size() >= kMaxRois || !(time_s - past_rois_.front().time_s < max_age))) {
    past_rois_.pop_front();
  }
  past_rois_.push_back({time_s, view, roi});
  const cv::Rect whole(0, 0, output_.width(), output_.height());
  cv::Rect learn = roi;
  for (const PastRoi& p : past_rois_) learn |= MapRect(HomographyBetween(view, p.view), p.roi, whole);
  return learn & whole;
}

void Compositor::UpdatePlate(const cv::Mat& background, const cv::Rect& learn,
                             const cv::Rect& active, const cv::Mat& raw) {
  // The plate learns this frame's scene around the subject (what it may
  // uncover next): over the matte's low roi where the matte knows the scene
  // to be, beyond it everywhere (beyond the matte's search, the scene), and
  // away from the subject's edge.
  const int s = matte_.scale();
  const cv::Rect& rl = matte_.low_roi();
  const cv::Rect view_rl(rl.x * s, rl.y * s, rl.width * s, rl.height * s);
  const cv::Rect update = learn & cv::Rect(0, 0, background.cols, background.rows);
  if (update.empty() || matte_.scene_known_low().empty()) return;
  // Blocked (255) where the scene is not known, in 1/255 steps like the
  // matte, and within plate_distance_px of the subject.
  blocked_.create(update.size(), CV_8U);
  blocked_.setTo(cv::Scalar(0));
  const cv::Rect known = view_rl & update;
  if (!known.empty()) {
    matte_.scene_known_low().convertTo(unknown_, CV_8U, -255.0, 255.0);
    cv::resize(unknown_, unknown_up_, view_rl.size(), 0, 0, cv::INTER_NEAREST);
    unknown_up_(known - view_rl.tl()).copyTo(blocked_(known - update.tl()));
  }
  const cv::Rect a = active & update;
  if (!a.empty()) {
    const int g = 2 * options_.plate_distance_px + 1;
    cv::Mat raw8;
    raw.convertTo(raw8, CV_8U, 255.0);
    cv::dilate(raw8, raw8, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(g, g)));
    cv::Mat b = blocked_(a - update.tl());
    cv::max(b, raw8(a - active.tl()), b);
  }
  plate_.Update(background(update), blocked_, update, static_cast<float>(options_.plate_below),
                options_.plate_row_step, frame_++);
}

void Compositor::FillUncovered(const cv::Mat& subject, cv::Mat* out) {
  // Where the background layer shows the subject (m_b) and the subject
  // layer does not (1 - m_s), the plate (freshness v), else the fallback.
  const cv::Rect& rb = report_.background_roi;
  if (keep_plate_) {
    plate_weight_ = cv::Mat::zeros(rb.size(), CV_32F);
    plate_sample_ = cv::Mat::zeros(rb.size(), out->type());
  }
  double uncovered[composite_internal::kRowStripes] = {};
  double filled[composite_internal::kRowStripes] = {};
  composite_internal::ForRowStripes(rb.height, [&](int k, int y0, int y1) {
    for (int y = y0; y < y1; ++y) FillRow(subject, y, &uncovered[k], &filled[k], out);
  });
  double all = 0.0, plate = 0.0;
  for (int k = 0; k < composite_internal::kRowStripes; ++k) all += uncovered[k], plate += filled[k];
  report_.matte_mean = cv::sum(matte_b8_)[0] / 255.0 / std::max(1, rb.area());
  report_.uncovered_px = all;
  report_.plate_share = all > 0.0 ? plate / all : 0.0;
  report_.fallback_share = all > 0.0 ? 1.0 - report_.plate_share : 0.0;
}

void Compositor::FillRow(const cv::Mat& subject, int y, double* uncovered, double* filled,
                         cv::Mat* out) {
  const cv::Rect& rb = report_.background_roi;
  const cv::Rect& rs = report_.subject_roi;
  const int cn = out->channels();
  const Eigen::Matrix3d& G = plate_.view_to_plate();
  uchar scratch[4];
  const int Y = rb.y + y;
  const uchar* mb = matte_b8_.ptr<uchar>(y);
  const uchar* S = subject.ptr<uchar>(Y) + cn * rb.x;
  uchar* O = out->ptr<uchar>(Y) + cn * rb.x;
  uchar* P = keep_plate_ ? plate_sample_.ptr<uchar>(y) : nullptr;
  const bool in_s = Y >= rs.y && Y < rs.y + rs.height;
  const uchar* ms = in_s ? matte_s_.ptr<uchar>(Y - rs.y) : nullptr;
  float* w = keep_plate_ ? plate_weight_.ptr<float>(y) : nullptr;
  // The plate pixel of the row's first output pixel, stepped along the row.
  const Eigen::Vector3d q0 = G * Eigen::Vector3d(rb.x, Y, 1.0);
  for (int x = 0; x < rb.width; ++x) {
    if (mb[x] == 0) continue;
    const int X = rb.x + x;
    const float m = mb[x] * (1.0f / 255.0f);
    const float m_s = in_s && X >= rs.x && X < rs.x + rs.width ? ms[X - rs.x] * (1.0f / 255.0f) : 0.0f;
    // The subject covers it (Blend draws it), or what would show of the
    // fill under it is negligible.
    if (m * (1.0f - m_s) < kFillNone) continue;
    uchar* p = P != nullptr ? P + cn * x : scratch;
    const Eigen::Vector3d q = q0 + x * G.col(0);
    const float v = plate_.SamplePlate(q.x() / q.z(), q.y() / q.z(), p);
    *uncovered += m * (1.0f - m_s);
    *filled += m * v * (1.0f - m_s);
    if (w != nullptr) w[x] = m * v * (1.0f - m_s);
    const float wp = m * v, wf = m * (1.0f - v);
    for (int c = 0; c < cn; ++c) {
      const float b = O[cn * x + c];
      O[cn * x + c] = cv::saturate_cast<uchar>(b + wp * (p[c] - b) + wf * (S[cn * x + c] - b));
    }
  }
}

void Compositor::Blend(const cv::Mat& subject, cv::Mat* out) {
  // out += m_s (S - out), in 1/256 steps; a whole subject pixel is copied.
  const cv::Rect& rs = report_.subject_roi;
  const int cn = out->channels();
  composite_internal::ForRowStripes(rs.height, [&](int, int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const uchar* m = matte_s_.ptr<uchar>(y);
      const uchar* S = subject.ptr<uchar>(rs.y + y) + cn * rs.x;
      uchar* O = out->ptr<uchar>(rs.y + y) + cn * rs.x;
      for (int x = 0; x < rs.width; ++x) {
        if (m[x] == 0) continue;
        if (m[x] == 255) {
          for (int c = cn * x; c < cn * (x + 1); ++c) O[c] = S[c];
          continue;
        }
        const int w = m[x] + (m[x] >> 7);  // 0..255 -> 0..256
        for (int c = cn * x; c < cn * (x + 1); ++c) {
          O[c] = static_cast<uchar>(O[c] + ((w * (S[c] - O[c]) + 128) >> 8));
        }
      }
    }
  });
}

}  // namespace steadiface
