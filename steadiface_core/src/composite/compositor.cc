#include "steadiface_core/composite/compositor.h"

#include <chrono>

#include <opencv2/imgproc.hpp>

namespace steadiface {
namespace {

double MsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

Status ValidateCompositeOptions(const CompositeOptions& o) {
  Status s = ValidateSubjectMatteOptions(o.matte);
  if (!s.ok()) return s;
  s = ValidateBackgroundPlateOptions(o.plate);
  if (!s.ok()) return s;
  if (!(o.plate_below >= 0.0 && o.plate_below <= 1.0)) {
    return Status::Error("composite: plate_below must be in [0, 1]");
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
  const cv::Rect whole(0, 0, size.width, size.height);
  const cv::Rect roi_b = matte_.Roi(region, size);
  report_.plate_restarts = plate_.restarts();
  report_.plate_reprojections = plate_.reprojections();
  if (roi_b.empty()) {
    matte_b_.release();
    matte_s_.release();
    plate_weight_.release();
    plate_sample_.release();
    return Status::Ok();
  }
  report_.active = true;
  report_.background_roi = roi_b;
  auto t0 = std::chrono::steady_clock::now();
  MatteInputs in;
  in.background = background;
  in.subject = subject;
  in.background_view = background_view;
  in.subject_view = subject_view;
  in.region = region;
  in.roi = roi_b;
  plate_.Sample(roi_b, &in.plate, &in.plate_valid);
  report_.plate_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();
  cv::Mat raw;
  matte_.Estimate(in, &raw);
  matte_b_ = raw * region.blend;
  report_.matte_mean = cv::mean(matte_b_)[0];
  // The matte in the subject layer's view.
  const Eigen::Matrix3d H_sb = HomographyBetween(subject_view, background_view);
  const Eigen::Matrix3d H_bs = HomographyBetween(background_view, subject_view);
  const cv::Rect roi_s = MapRect(H_sb, roi_b, whole);
  report_.subject_roi = roi_s;
  if (!roi_s.empty()) {
    cv::warpPerspective(matte_b_, matte_s_, RectMap(H_bs, roi_b, 1.0, roi_s, 1.0), roi_s.size(),
                        cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                        cv::Scalar(0));
  } else {
    matte_s_.release();
  }
  report_.matte_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();
  FillUncovered(subject, in.plate, in.plate_valid, out);
  plate_sample_ = in.plate;
  if (!roi_s.empty()) Blend(subject, out);
  report_.blend_ms = MsSince(t0);
  // The plate learns this frame's scene, away from the subject's edge.
  t0 = std::chrono::steady_clock::now();
  cv::Mat grown;
  const int g = 2 * options_.plate_distance_px + 1;
  cv::dilate(raw, grown, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(g, g)));
  grown.setTo(1.0f, matte_.scene_known() < 0.5f);
  plate_.Update(background(roi_b), grown, roi_b, static_cast<float>(options_.plate_below));
  report_.plate_ms += MsSince(t0);
  report_.plate_coverage = plate_.Coverage();
  report_.plate_restarts = plate_.restarts();
  report_.plate_reprojections = plate_.reprojections();
  return Status::Ok();
}

void Compositor::FillUncovered(const cv::Mat& subject, const cv::Mat& plate, const cv::Mat& valid,
                               cv::Mat* out) {
  const cv::Rect& rb = report_.background_roi;
  const cv::Rect& rs = report_.subject_roi;
  const int cn = out->channels();
  plate_weight_.create(rb.size(), CV_32F);
  double uncovered = 0.0, filled = 0.0;
  for (int y = 0; y < rb.height; ++y) {
    const int Y = rb.y + y;
    const float* mb = matte_b_.ptr<float>(y);
    const float* v = valid.ptr<float>(y);
    const uchar* P = plate.ptr<uchar>(y);
    const uchar* S = subject.ptr<uchar>(Y) + cn * rb.x;
    uchar* O = out->ptr<uchar>(Y) + cn * rb.x;
    const bool in_s = Y >= rs.y && Y < rs.y + rs.height;
    const float* ms = in_s ? matte_s_.ptr<float>(Y - rs.y) : nullptr;
    float* w = plate_weight_.ptr<float>(y);
    for (int x = 0; x < rb.width; ++x) {
      const int X = rb.x + x;
      const float m_s = in_s && X >= rs.x && X < rs.x + rs.width ? ms[X - rs.x] : 0.0f;
      const float m = mb[x];
      w[x] = m * v[x] * (1.0f - m_s);
      if (m <= 0.0f) continue;
      uncovered += m * (1.0f - m_s);
      filled += w[x];
      const float wp = m * v[x], wf = m * (1.0f - v[x]);
      for (int c = cn * x; c < cn * (x + 1); ++c) {
        const float b = O[c];
        O[c] = cv::saturate_cast<uchar>(b + wp * (P[c] - b) + wf * (S[c] - b));
      }
    }
  }
  report_.uncovered_px = uncovered;
  report_.plate_share = uncovered > 0.0 ? filled / uncovered : 0.0;
  report_.fallback_share = uncovered > 0.0 ? 1.0 - report_.plate_share : 0.0;
}

void Compositor::Blend(const cv::Mat& subject, cv::Mat* out) {
  const cv::Rect& rs = report_.subject_roi;
  const int cn = out->channels();
  for (int y = 0; y < rs.height; ++y) {
    const float* m = matte_s_.ptr<float>(y);
    const uchar* S = subject.ptr<uchar>(rs.y + y) + cn * rs.x;
    uchar* O = out->ptr<uchar>(rs.y + y) + cn * rs.x;
    for (int x = 0; x < rs.width; ++x) {
      if (m[x] <= 0.0f) continue;
      for (int c = cn * x; c < cn * (x + 1); ++c) {
        O[c] = cv::saturate_cast<uchar>(O[c] + m[x] * (S[c] - O[c]));
      }
    }
  }
}

}  // namespace steadiface
