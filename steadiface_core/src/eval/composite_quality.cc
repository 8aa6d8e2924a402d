#include "steadiface_core/eval/composite_quality.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgcodecs.hpp>

#include "steadiface_core/composite/layer_homography.h"
#include <opencv2/imgproc.hpp>
#include <opencv2/video/background_segm.hpp>

namespace steadiface {
namespace eval {
namespace {

// Mean of |a - b| over pixels where either is above zero.
double MeanChange(const cv::Mat& a, const cv::Mat& b) {
  double sum = 0.0;
  int n = 0;
  for (int y = 0; y < a.rows; ++y) {
    const float* p = a.ptr<float>(y);
    const float* q = b.ptr<float>(y);
    for (int x = 0; x < a.cols; ++x) {
      if (p[x] > 0.0f || q[x] > 0.0f) {
        sum += std::abs(p[x] - q[x]);
        ++n;
      }
    }
  }
  return n > 0 ? sum / n : 0.0;
}

// Mean absolute difference over `used` (grey levels, mean over channels),
// added to *error weighted by the pixel count, which goes to *pixels.
void AddError(const cv::Mat& a, const cv::Mat& b, const cv::Mat& used, double* error,
              double* pixels) {
  const double n = cv::countNonZero(used);
  if (n <= 0) return;
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  const cv::Scalar m = cv::mean(diff, used);
  double e = 0.0;
  for (int ch = 0; ch < diff.channels(); ++ch) e += m[ch];
  *error += n * e / diff.channels();
  *pixels += n;
}

// The IoU of two masks outside the band `k` draws around the true outline;
// NaN when the truth has too little area there.
double BandIou(const cv::Mat& T, const cv::Mat& E, const cv::Mat& k) {
  cv::Mat grown, shrunk;
  cv::dilate(T, grown, k);
  cv::erode(T, shrunk, k);
  const cv::Mat scored = ~(grown & ~shrunk);
  if (cv::countNonZero(T & scored) < 200) return NAN;
  const double uni = cv::countNonZero((T | E) & scored);
  return uni > 0 ? cv::countNonZero(T & E & scored) / uni : 1.0;
}

// The structuring element of the band left out around the true outline.
cv::Mat EdgeBand() {
  const int k = 2 * CompositeQuality::kEdgeBandPx + 1;
  return cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k));
}

}  // namespace

Status CompositeQuality::Create(const sim::Simulator& sim, const Pipeline& pipeline,
                                std::unique_ptr<CompositeQuality>* out) {
  WarpOptions w = pipeline.options().warp;
  w.mode = WarpMode::kGlobal;
  std::unique_ptr<CompositeQuality> q(new CompositeQuality(sim));
  const Status s = Warper::Create(pipeline.camera_model(), w, &q->warper_);
  if (!s.ok()) return s;
  const CompositeOptions& co = pipeline.options().composite;
  q->ideal_plate_.reset(new BackgroundPlate(q->warper_->output_geometry(), co.plate));
  q->plate_distance_px_ = co.plate_distance_px;
  q->plate_below_ = static_cast<float>(co.plate_below);
  *out = std::move(q);
  return Status::Ok();
}



Status CompositeQuality::Add(int index, const Pipeline& pipeline, const PipelineFrame& f,
                             const cv::Mat& input) {
  const Compositor* c = pipeline.compositor();
  if (c == nullptr || f.output.empty()) return Status::Ok();
  warper_->SetCropRatio(f.crop.crop_ratio);
  cv::Mat scene, alpha, truth8, scene_out;
  Status s = sim_.RenderTruthLayers(index, &scene, &alpha);
  const StabilizerFrame::LayerPose& b = f.stabilizer.background;
  const Eigen::Quaterniond R_b = b.valid ? b.R_v : f.stabilizer.R_v;
  const Eigen::Vector2d t_b = b.valid ? b.t : f.stabilizer.t;
  if (s.ok()) s = warper_->Warp(alpha, R_b, t_b, f.stabilizer.rows, &truth8);
  if (s.ok()) s = warper_->Warp(scene, R_b, t_b, f.stabilizer.rows, &scene_out);
  cv::Mat alpha_s;  // the true subject in the subject layer's view
  if (s.ok()) s = warper_->Warp(alpha, f.stabilizer.R_v, f.stabilizer.t, f.stabilizer.rows, &alpha_s);
  if (!s.ok()) return s;
  if (f.output.type() == scene_out.type()) {
    // Clearly uncovered: the subject's own soft edge (which the subject
    // layer rightly draws) left out on both sides.
    AddError(f.output, scene_out, (truth8 >= 242) & (alpha_s <= 12), &uncovered_error_,
             &uncovered_pixels_);
  }
  cv::Mat truth, matte = cv::Mat::zeros(truth8.size(), CV_32F);
  truth8.convertTo(truth, CV_32F, 1.0 / 255.0);
  const CompositeReport& r = f.composite.report;
  if (r.active && !c->background_matte().empty()) {
    c->background_matte().copyTo(matte(r.background_roi));
  }
  AddMatte(index, truth, matte);
  if (!input.empty()) {
    cv::Mat picture;
    s = warper_->Warp(input, R_b, t_b, f.stabilizer.rows, &picture);
    if (!s.ok()) return s;
    AddSubtractors(truth, picture);
  }
  ideal_plate_->Begin(OutputView(warper_->output_geometry(), R_b, t_b),
                      ToSeconds(sim_.Truth(index).stamp));
  AddPlate(*c, r, truth, scene_out);
  uncovered_ += r.uncovered_px;
  fallback_ += r.uncovered_px * r.fallback_share;
  if (!previous_.empty()) {
    change_ += MeanChange(matte, previous_);
    truth_change_ += MeanChange(truth, previous_truth_);
    ++changes_;
  }
  previous_ = matte;
  previous_truth_ = truth;
  if (!dump_prefix_.empty() && index % dump_every_ == 0) {
    Dump(index, *c, f, truth, matte, scene_out);
  }
  return Status::Ok();
}

void CompositeQuality::AddMatte(int index, const cv::Mat& truth, const cv::Mat& matte) {
  // IoU outside the band around the true outline.
  const cv::Mat T = truth >= 0.5, E = matte >= 0.5;
  const double iou = BandIou(T, E, EdgeBand());
  if (!std::isfinite(iou)) return;
  iou_.push_back(iou);
  iou_frames_.push_back(index);
  // The matte's outline against the true one.
  cv::Mat edge_t, edge_e, dist;
  cv::morphologyEx(T, edge_t, cv::MORPH_GRADIENT, cv::Mat());
  cv::morphologyEx(E, edge_e, cv::MORPH_GRADIENT, cv::Mat());
  cv::distanceTransform(~edge_t, dist, cv::DIST_L2, 3);
  edge_.push_back(cv::countNonZero(edge_e) > 0 ? cv::mean(dist, edge_e)[0] : NAN);
}

void CompositeQuality::AddSubtractors(const cv::Mat& truth, const cv::Mat& picture) {
  if (mog2_.empty()) {
    mog2_ = cv::createBackgroundSubtractorMOG2(500, 16.0, false);
    knn_ = cv::createBackgroundSubtractorKNN(500, 400.0, false);
  }
  const cv::Mat T = truth >= 0.5;
  cv::Mat fg;
  mog2_->apply(picture, fg);
  const double m = BandIou(T, fg > 127, EdgeBand());
  knn_->apply(picture, fg);
  const double n = BandIou(T, fg > 127, EdgeBand());
  if (std::isfinite(m)) mog2_iou_.push_back(m);
  if (std::isfinite(n)) knn_iou_.push_back(n);
}

void CompositeQuality::AddPlate(const Compositor& c, const CompositeReport& r,
                                const cv::Mat& truth, const cv::Mat& scene_out) {
  // The plate where it filled the output, and the ideal plate there; then
  // the ideal plate learns this frame where the true subject is not.
  const bool used_plate = r.active && !c.plate_weight().empty() && !c.plate_sample().empty();
  if (used_plate) {
    cv::Mat ideal, ideal_valid;
    ideal_plate_->Sample(r.background_roi, &ideal, &ideal_valid);
    AddError(ideal, scene_out(r.background_roi),
             (c.plate_weight() >= 0.5) & (ideal_valid >= 0.5), &ideal_error_, &ideal_pixels_);
    AddError(c.plate_sample(), scene_out(r.background_roi), c.plate_weight() >= 0.5,
             &plate_error_, &plate_pixels_);
  }
  if (r.active) {
    const int g = 2 * plate_distance_px_ + 1;
    cv::Mat grown;
    cv::dilate(truth(r.background_roi), grown,
               cv::getStructuringElement(cv::MORPH_RECT, cv::Size(g, g)));
    ideal_plate_->Update(scene_out(r.background_roi), grown, r.background_roi, plate_below_);
  }
}

void CompositeQuality::Dump(int index, const Compositor& c, const PipelineFrame& f,
                            const cv::Mat& truth, const cv::Mat& matte,
                            const cv::Mat& scene_out) const {
  // Output | matte against truth (white both, red missed, blue extra) | the
  // plate's weight (green) and its error against the true scene (red, x4)
  // where it is used.
  const CompositeReport& r = f.composite.report;
  cv::Mat out3, m3(matte.size(), CV_8UC3), w3 = cv::Mat::zeros(matte.size(), CV_8UC3);
  if (f.output.channels() == 1) {
    cv::cvtColor(f.output, out3, cv::COLOR_GRAY2BGR);
  } else {
    out3 = f.output;
  }
  for (int y = 0; y < matte.rows; ++y) {
    for (int x = 0; x < matte.cols; ++x) {
      const uchar e = cv::saturate_cast<uchar>(255 * matte.at<float>(y, x));
      const uchar t = cv::saturate_cast<uchar>(255 * truth.at<float>(y, x));
      m3.at<cv::Vec3b>(y, x) = cv::Vec3b(e, std::min(e, t), t);
    }
  }
  if (r.active && !c.plate_weight().empty() && !c.plate_sample().empty()) {
    cv::Mat w8, diff, grey;
    c.plate_weight().convertTo(w8, CV_8U, 255.0);
    cv::absdiff(c.plate_sample(), scene_out(r.background_roi), diff);
    if (diff.channels() == 1) {
      grey = diff;
    } else {
      cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
    }
    grey.convertTo(grey, CV_8U, 4.0);
    grey.setTo(0, c.plate_weight() < 0.5);
    std::vector<cv::Mat> ch = {cv::Mat::zeros(w8.size(), CV_8U), w8, grey};
    cv::merge(ch, w3(r.background_roi));
  }
  cv::Mat row;
  cv::hconcat(std::vector<cv::Mat>{out3, m3, w3}, row);
  char name[32];
  std::snprintf(name, sizeof(name), "_%03d.png", index);
  cv::imwrite(dump_prefix_ + name, row);
}

CompositeQualityScore CompositeQuality::Compute() const {
  CompositeQualityScore q;
  q.frames = static_cast<int>(iou_.size());
  if (!iou_.empty()) {
    double sum = 0.0;
    q.matte_iou_min = 2.0;
    for (size_t i = 0; i < iou_.size(); ++i) {
      sum += iou_[i];
      if (iou_[i] < q.matte_iou_min) {
        q.matte_iou_min = iou_[i];
        q.matte_iou_min_frame = iou_frames_[i];
      }
    }
    q.matte_iou_mean = sum / iou_.size();
    const int settled = static_cast<int>(std::lround(0.5 * sim_.options().fps));
    for (size_t i = 0; i < iou_.size(); ++i) {
      if (iou_frames_[i] < settled) continue;
      if (!(iou_[i] >= q.matte_iou_min_settled)) {
        q.matte_iou_min_settled = iou_[i];
        q.matte_iou_min_settled_frame = iou_frames_[i];
      }
    }
    double e = 0.0, step = 0.0;
    int n = 0;
    for (size_t i = 0; i < edge_.size(); ++i) {
      if (!std::isfinite(edge_[i])) continue;
      e += edge_[i];
      ++n;
      if (i > 0 && std::isfinite(edge_[i - 1])) step = std::max(step, std::abs(edge_[i] - edge_[i - 1]));
    }
    if (n > 0) q.edge_error_px = e / n;
    q.edge_max_step_px = step;
  }
  auto mean = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return v.empty() ? NAN : sum / v.size();
  };
  q.mog2_iou_mean = mean(mog2_iou_);
  q.knn_iou_mean = mean(knn_iou_);
  if (plate_pixels_ > 0.0) q.plate_mae = plate_error_ / plate_pixels_;
  q.plate_pixels = plate_pixels_;
  if (ideal_pixels_ > 0.0) q.ideal_plate_mae = ideal_error_ / ideal_pixels_;
  q.ideal_plate_pixels = ideal_pixels_;
  if (uncovered_ > 0.0) q.fallback_share = fallback_ / uncovered_;
  if (uncovered_pixels_ > 0.0) q.uncovered_mae = uncovered_error_ / uncovered_pixels_;
  q.uncovered_pixels = uncovered_pixels_;
  if (changes_ > 0) {
    q.matte_change = change_ / changes_;
    q.truth_change = truth_change_ / changes_;
  }
  return q;
}

}  // namespace eval
}  // namespace steadiface
