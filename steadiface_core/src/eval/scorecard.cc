#include "steadiface_core/eval/scorecard.h"

#include "steadiface_core/composite/layer_homography.h"

#include "steadiface_core/common/high_pass_rms.h"
#include "steadiface_core/common/percentile.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Eigenvalues>
#include <opencv2/core.hpp>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/layered/layer_blend.h"
#include "eval/longest_run.h"

namespace steadiface {
namespace eval {
namespace {

// Raises *step and *accel to the largest first and second differences of a
// trajectory over consecutive finite samples; false when there is no pair.
bool LargestSteps(const std::vector<Eigen::Vector2d>& p, double* step, double* accel) {
  bool any = false;
  for (size_t t = 1; t < p.size(); ++t) {
    if (!p[t].allFinite() || !p[t - 1].allFinite()) continue;
    any = true;
    *step = std::max(*step, (p[t] - p[t - 1]).norm());
    if (t >= 2 && p[t - 2].allFinite()) {
      *accel = std::max(*accel, (p[t] - 2.0 * p[t - 1] + p[t - 2]).norm());
    }
  }
  return any;
}

// Power spectrum of a real series (DFT), bins 0..n/2.
std::vector<double> Power(const std::vector<double>& x) {
  cv::Mat in(1, static_cast<int>(x.size()), CV_64F), out;
  for (size_t i = 0; i < x.size(); ++i) in.at<double>(0, static_cast<int>(i)) = x[i];
  cv::dft(in, out, cv::DFT_COMPLEX_OUTPUT);
  std::vector<double> p(x.size() / 2 + 1);
  for (size_t k = 0; k < p.size(); ++k) {
    const cv::Vec2d c = out.at<cv::Vec2d>(0, static_cast<int>(k));
    p[k] = c[0] * c[0] + c[1] * c[1];
  }
  return p;
}

// Inverts a warp mesh (output vertices -> input px) at input pixel p: the
// output pixel whose bilinear source is p. Cells whose source quad's box
// holds p are tried by Newton; without one, the nearest cell's bilinear
// map is extrapolated.
bool InvertMesh(const FrameWarp& w, const Eigen::Vector2d& p, Eigen::Vector2d* out) {
  const int cols = static_cast<int>(w.mesh_u.size()), rows = static_cast<int>(w.mesh_v.size());
  if (cols < 2 || rows < 2 || w.mesh_source.size() != static_cast<size_t>(cols * rows)) return false;
  auto src = [&](int i, int j) { return w.mesh_source[j * cols + i].cast<double>().eval(); };
  auto newton = [&](int i, int j, bool clamp, Eigen::Vector2d* o) {
    const Eigen::Vector2d A = src(i, j), B = src(i + 1, j), C = src(i + 1, j + 1), E = src(i, j + 1);
    double a = 0.5, b = 0.5;
    for (int it = 0; it < 12; ++it) {
      const Eigen::Vector2d S = (1 - a) * (1 - b) * A + a * (1 - b) * B + (1 - a) * b * E + a * b * C;
      Eigen::Matrix2d J;
      J.col(0) = (1 - b) * (B - A) + b * (C - E);
      J.col(1) = (1 - a) * (E - A) + a * (C - B);
      if (std::abs(J.determinant()) < 1e-12) return false;
      const Eigen::Vector2d step = J.inverse() * (p - S);
      a += step.x();
      b += step.y();
      if (step.norm() < 1e-9) break;
    }
    const double tol = 1e-6;
    if (clamp && (a < -tol || a > 1 + tol || b < -tol || b > 1 + tol)) return false;
    const Eigen::Vector2d S = (1 - a) * (1 - b) * A + a * (1 - b) * B + (1 - a) * b * E + a * b * C;
    if ((S - p).norm() > 1e-4) return false;
    *o = Eigen::Vector2d(w.mesh_u[i] + a * (w.mesh_u[i + 1] - w.mesh_u[i]),
                         w.mesh_v[j] + b * (w.mesh_v[j + 1] - w.mesh_v[j]));
    return true;
  };
  double best = std::numeric_limits<double>::infinity();
  int bi = 0, bj = 0;
  for (int j = 0; j + 1 < rows; ++j) {
    for (int i = 0; i + 1 < cols; ++i) {
      const Eigen::Vector2d A = src(i, j), B = src(i + 1, j), C = src(i + 1, j + 1), E = src(i, j + 1);
      const Eigen::Vector2d lo = A.cwiseMin(B).cwiseMin(C).cwiseMin(E);
      const Eigen::Vector2d hi = A.cwiseMax(B).cwiseMax(C).cwiseMax(E);
      if (p.x() >= lo.x() - 1e-6 && p.y() >= lo.y() - 1e-6 && p.x() <= hi.x() + 1e-6 &&
          p.y() <= hi.y() + 1e-6 && newton(i, j, true, out)) {
        return true;
      }
      const double d = (0.25 * (A + B + C + E) - p).squaredNorm();
      if (d < best) {
        best = d;
        bi = i;
        bj = j;
      }
    }
  }
  return newton(bi, bj, false, out);
}

// Largest distance of 2D points from their total-least-squares line.
double LineDeviation(const std::vector<Eigen::Vector2d>& pts) {
  if (pts.size() < 3) return 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& q : pts) mean += q;
  mean /= static_cast<double>(pts.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& q : pts) cov += (q - mean) * (q - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  const Eigen::Vector2d normal = es.eigenvectors().col(0);  // smallest eigenvalue
  double worst = 0.0;
  for (const auto& q : pts) worst = std::max(worst, std::abs(normal.dot(q - mean)));
  return worst;
}

}  // namespace

double Scorecard::Stability(const std::vector<Eigen::Vector2d>& x) {
  if (x.size() < 16) return 0.0;
  double score = 0.0;
  for (int axis = 0; axis < 2; ++axis) {
    std::vector<double> d;
    for (size_t i = 1; i < x.size(); ++i) d.push_back(x[i][axis] - x[i - 1][axis]);
    const std::vector<double> p = Power(d);
    double low = 0.0, all = 0.0;
    for (size_t k = 1; k < p.size(); ++k) {
      all += p[k];
      if (k >= 1 && k <= 5) low += p[k];  // 2nd-6th lowest bins (DC is the 1st)
    }
    score += all > 0 ? low / all : 1.0;
  }
  return 0.5 * score;
}

Scorecard::Scorecard(const sim::Simulator& sim, const CameraModel& model,
                     const OutputGeometry& output, const ScorecardOptions& options)
    : sim_(sim),
      model_(model),
      output_(output),
      options_(options),
      frame_output_(output),
      frame_protrusion_(model, output, 16) {
  // Far-background directions: a grid over the views the camera sweeps
  // (several along a pan); each is scored on its longest in-view run.
  const double T = sim.options().duration_s;
  for (double f : {0.1, 0.5, 0.9}) {
    const Eigen::Quaterniond R = sim.CameraPose(f * T).R;
    for (double y : {-0.15, 0.0, 0.15}) {
      for (double x : {-0.25, 0.0, 0.25}) {
        background_dirs_.push_back(R * Eigen::Vector3d(x, y, 1.0));
      }
    }
  }
  background_out_.resize(background_dirs_.size());
  // The visible-background grid, denser and within the output crop.
  for (double f : {0.1, 0.5, 0.9}) {
    const Eigen::Quaterniond R = sim.CameraPose(f * T).R;
    for (int yi = 0; yi < 5; ++yi) {
      for (int xi = 0; xi < 9; ++xi) {
        visible_dirs_.push_back(R * Eigen::Vector3d(-0.4 + 0.1 * xi, -0.22 + 0.11 * yi, 1.0));
      }
    }
  }
  visible_out_.resize(visible_dirs_.size());
  // Straight world lines (great circles) seen from the middle of the
  // sequence: three horizontal, four vertical.
  const Eigen::Quaterniond Rm = sim.CameraPose(0.5 * T).R;
  for (double y : {-0.15, 0.0, 0.15}) {
    std::vector<Eigen::Vector3d> line;
    for (int k = 0; k <= 60; ++k) line.push_back(Rm * Eigen::Vector3d(-0.6 + 0.02 * k, y, 1.0));
    lines_.push_back(line);
  }
  for (double x : {-0.3, -0.15, 0.15, 0.3}) {
    std::vector<Eigen::Vector3d> line;
    for (int k = 0; k <= 40; ++k) line.push_back(Rm * Eigen::Vector3d(x, -0.4 + 0.02 * k, 1.0));
    lines_.push_back(line);
  }
}

bool Scorecard::MapToOutput(const FrameWarp& w, const Eigen::Vector2d& p,
                            Eigen::Vector2d* out) const {
  switch (w.kind) {
    case FrameWarp::Kind::kIdentity:
      *out = p;
      return true;
    case FrameWarp::Kind::kHomography: {
      const Eigen::Vector3d q = w.H * p.homogeneous();
      if (std::abs(q.z()) < 1e-12) return false;
      *out = q.hnormalized();
      return true;
    }
    case FrameWarp::Kind::kMesh:
      return InvertMesh(w, p, out);
    case FrameWarp::Kind::kComposite:  // the far scene: the background layer
    case FrameWarp::Kind::kPose: {
      const bool bg = w.kind == FrameWarp::Kind::kComposite;
      Eigen::Vector2d V;
      if (!model_.Project(model_.PixelToNormalized(p), bg ? w.R_b : w.R_v, bg ? w.t_b : w.t,
                          w.rows.At(p.y()), &V)) {
        return false;
      }
      *out = frame_output_.VirtualToOutputPixel(V);
      return true;
    }
  }
  return false;
}

bool Scorecard::CompositeCovers(int index, const FrameWarp& w, const Eigen::Vector2d& o) const {
  // The direction the subject layer shows at o, and where it is in the input.
  const LayerView v = OutputView(frame_output_, w.R_v, w.t);
  const Eigen::Vector3d d = v.R.conjugate() * (v.K.inverse() * o.homogeneous());
  Eigen::Vector2d px;
  const CameraIntrinsics& ki = sim_.intrinsics();
  return sim_.BackgroundPixel(index, d.normalized(), &px) && px.x() >= 0 && px.y() >= 0 &&
         px.x() <= ki.width - 1 && px.y() <= ki.height - 1 && sim_.SubjectCovers(index, px);
}

void Scorecard::Add(int index, const FrameWarp& w) {
  const sim::SimTruth truth = sim_.Truth(index);
  const double r = std::isfinite(w.crop_ratio) ? w.crop_ratio : output_.crop_ratio();
  if (r != frame_output_.crop_ratio()) {
    frame_output_ = output_.WithCropRatio(r);
    frame_protrusion_ = ProtrusionGeometry(model_, frame_output_, 16);
  }
  // A homography's view: the input's width over its scale (a peer's zoom).
  const double scale = std::sqrt(std::abs(w.H.topLeftCorner<2, 2>().determinant()));
  kept_width_.push_back(w.kind == FrameWarp::Kind::kIdentity     ? 1.0
                        : w.kind == FrameWarp::Kind::kHomography ? std::min(1.0, 1.0 / scale)
                                                                 : 1.0 - 2.0 * r);
  Sample s;
  s.t = ToSeconds(truth.stamp);
  s.crop_ratio = r;
  s.crop_need = w.crop_need;
  s.head_in = truth.head_px;
  FrameWarp subject = w;  // the head: the subject layer's pose
  if (w.kind == FrameWarp::Kind::kComposite) subject.kind = FrameWarp::Kind::kPose;
  s.head_valid = truth.head_in_view && MapToOutput(subject, truth.head_px, &s.head_out);
  if (!s.head_valid) s.head_out = Eigen::Vector2d::Constant(NAN);
  head_out_.push_back(s.head_out);
  head_valid_.push_back(s.head_valid);
  const CameraIntrinsics& ki = sim_.intrinsics();
  for (size_t k = 0; k < background_dirs_.size(); ++k) {
    Eigen::Vector2d px, o = Eigen::Vector2d::Constant(NAN);
    if (sim_.BackgroundPixel(index, background_dirs_[k], &px) && px.x() >= 0 &&
        px.y() >= 0 && px.x() <= ki.width - 1 && px.y() <= ki.height - 1) {
      MapToOutput(w, px, &o);
    }
    background_out_[k].push_back(o);
    if (k == 13) s.background_out = o;  // centre of the middle view
  }
  if (w.kind != FrameWarp::Kind::kIdentity) identity_ = false;
  AddRoll(truth, w);
  head_target_out_.push_back(w.has_head_target ? frame_output_.VirtualToOutputPixel(w.head_target)
                                               : Eigen::Vector2d::Constant(NAN));
  AddVisibleBackground(index, w);
  if (w.kind == FrameWarp::Kind::kMesh) AddMesh(index, w);
  distortion_.push_back(CentreDistortion(w));
  undefined_ += Undefined(w, &s);
  AddStageTimes(w);
  AddRotation(truth, w);
  samples_.push_back(s);
}

void Scorecard::AddRoll(const sim::SimTruth& truth, const FrameWarp& w) {
  // The true up in the camera at the middle row; the output's camera is the
  // real one turned by R_out R_r^-1 (R_r the pipeline's middle row).
  if (truth.R_r.empty()) return;
  const Eigen::Quaterniond& R_true = truth.R_r[truth.R_r.size() / 2];  // world -> camera
  const Eigen::Vector3d up_cam = R_true * Eigen::Vector3d(0.0, -1.0, 0.0);
  input_roll_.push_back(std::atan2(up_cam.x(), -up_cam.y()));
  if (w.kind != FrameWarp::Kind::kPose && w.kind != FrameWarp::Kind::kComposite &&
      w.kind != FrameWarp::Kind::kMesh) {
    if (w.kind == FrameWarp::Kind::kIdentity) output_roll_.push_back(input_roll_.back());
    return;
  }
  if (w.rows.empty()) return;
  const Eigen::Quaterniond& R_out = w.kind == FrameWarp::Kind::kPose ? w.R_v : w.R_b;
  const Eigen::Vector3d up_out = R_out * (w.rows.Middle().conjugate() * up_cam);
  output_roll_.push_back(std::atan2(up_out.x(), -up_out.y()));
}

void Scorecard::AddVisibleBackground(int index, const FrameWarp& w) {
  const CameraIntrinsics& ki = sim_.intrinsics();
  // Visible background and straight lines: input pixels the subject does
  // not cover, landing inside the output image.
  const double ow = w.kind == FrameWarp::Kind::kIdentity ? ki.width : output_.width();
  const double oh = w.kind == FrameWarp::Kind::kIdentity ? ki.height : output_.height();
  auto visible_out = [&](const Eigen::Vector3d& d, Eigen::Vector2d* o) {
    Eigen::Vector2d px;
    return sim_.BackgroundPixel(index, d, &px) && px.x() >= 0 && px.y() >= 0 &&
           px.x() <= ki.width - 1 && px.y() <= ki.height - 1 &&
           (w.kind == FrameWarp::Kind::kComposite || !sim_.SubjectCovers(index, px)) &&
           MapToOutput(w, px, o) && o->x() >= 0 && o->y() >= 0 && o->x() <= ow - 1 &&
           o->y() <= oh - 1 &&
           (w.kind != FrameWarp::Kind::kComposite || !CompositeCovers(index, w, *o));
  };
  for (size_t k = 0; k < visible_dirs_.size(); ++k) {
    Eigen::Vector2d o;
    if (!visible_out(visible_dirs_[k], &o)) o = Eigen::Vector2d::Constant(NAN);
    visible_out_[k].push_back(o);
  }
  for (const auto& line : lines_) {
    std::vector<Eigen::Vector2d> run;
    auto flush = [&] {
      if (run.size() >= 5) {
        const double dev = LineDeviation(run);
        line_devs_.push_back(dev);
        if (dev > line_dev_) {
          line_dev_ = dev;
          line_dev_frame_ = index;
        }
      }
      run.clear();
    };
    for (const auto& d : line) {
      Eigen::Vector2d o;
      if (visible_out(d, &o)) {
        run.push_back(o);
      } else {
        flush();
      }
    }
    flush();
  }
}

void Scorecard::AddMesh(int index, const FrameWarp& w) {
  const int cols = static_cast<int>(w.mesh_u.size()), rows = static_cast<int>(w.mesh_v.size());
  std::vector<double> ratios;
  folded_ += CellRatios(cols, rows, w.mesh_u, w.mesh_v, w.mesh_source, nullptr, &ratios);
  cell_ratios_.insert(cell_ratios_.end(), ratios.begin(), ratios.end());
  for (double q : ratios) {
    if (q < min_ratio_) {
      min_ratio_ = q;
      min_ratio_frame_ = index;
    }
  }
  const size_t n = w.mesh_source.size();
  if (w.mesh_background.size() == n && w.mesh_blend.size() == n) {
    // Output px per input px, from the background mesh's middle row.
    const int j = rows / 2;
    double sum = 0.0, span = 0.0;
    for (int i = 0; i + 1 < cols; ++i) {
      sum += (w.mesh_background[j * cols + i + 1] - w.mesh_background[j * cols + i])
                 .cast<double>().norm();
      span += w.mesh_u[i + 1] - w.mesh_u[i];
    }
    const double zoom = sum > 0 ? span / sum : 1.0;
    const double g = *std::max_element(w.mesh_blend.begin(), w.mesh_blend.end());
    band_offsets_.resize(n);
    band_frames_.resize(n, 0);
    for (size_t k = 0; k < n; ++k) {
      band_offsets_[k].push_back(zoom * (w.mesh_source[k] - w.mesh_background[k]).cast<double>());
      if (w.mesh_blend[k] > 0.0 && w.mesh_blend[k] < 0.999 * g) ++band_frames_[k];
    }
  }
}

double Scorecard::CentreDistortion(const FrameWarp& w) const {
  // Local linear part at the output centre, via the input point
  // that lands there (numerically).
  double ratio = 1.0;
  if (w.kind != FrameWarp::Kind::kIdentity) {
    const Eigen::Vector2d c(0.5 * (sim_.intrinsics().width - 1), 0.5 * (sim_.intrinsics().height - 1));
    Eigen::Vector2d o0, ox, oy;
    const double h = 1.0;
    if (MapToOutput(w, c, &o0) && MapToOutput(w, c + Eigen::Vector2d(h, 0), &ox) &&
        MapToOutput(w, c + Eigen::Vector2d(0, h), &oy)) {
      Eigen::Matrix2d J;
      J.col(0) = (ox - o0) / h;
      J.col(1) = (oy - o0) / h;
      Eigen::JacobiSVD<Eigen::Matrix2d> svd(J);
      const auto sv = svd.singularValues();
      ratio = sv(0) > 0 ? sv(1) / sv(0) : 0.0;
    } else {
      ratio = 0.0;
    }
  }
  return ratio;
}

bool Scorecard::Undefined(const FrameWarp& w, Sample* s) const {
  // Also fills the sample's pose figures (kPose).
  const CameraIntrinsics& ki = sim_.intrinsics();
  bool undefined = false;
  if (w.kind == FrameWarp::Kind::kMesh) {
    // Bilinear cells: every pixel is defined when every vertex lands inside
    // the input frame.
    for (const auto& q : w.mesh_source) {
      if (!(q.x() >= 0 && q.y() >= 0 && q.x() <= ki.width - 1 && q.y() <= ki.height - 1)) {
        undefined = true;
      }
    }
  }
  if (w.kind == FrameWarp::Kind::kPose || w.kind == FrameWarp::Kind::kComposite) {
    undefined = !frame_protrusion_.Check(w.R_v, w.t, w.rows, 0.0).defined;
    if (w.kind == FrameWarp::Kind::kComposite) {
      undefined = undefined || !frame_protrusion_.Check(w.R_b, w.t_b, w.rows, 0.0).defined;
    }
    const Eigen::Vector3d v = LogSO3(w.R_v), r = LogSO3(w.rows.Middle());
    for (int i = 0; i < 3; ++i) {
      s->virtual_angle[i] = v[i];
      s->real_angle[i] = r[i];
    }
    s->offset = w.t;
  } else if (w.kind == FrameWarp::Kind::kHomography) {
    const Eigen::Matrix3d Hi = w.H.inverse();
    const double W = sim_.intrinsics().width - 1, Hh = sim_.intrinsics().height - 1;
    for (int i = 0; i <= 20 && !undefined; ++i) {
      const double f = i / 20.0;
      for (const Eigen::Vector2d& q : {Eigen::Vector2d(f * W, 0), Eigen::Vector2d(f * W, Hh),
                                       Eigen::Vector2d(0, f * Hh), Eigen::Vector2d(W, f * Hh)}) {
        const Eigen::Vector2d p = (Hi * q.homogeneous()).hnormalized();
        if (!(p.x() >= 0 && p.y() >= 0 && p.x() <= W && p.y() <= Hh)) undefined = true;
      }
    }
  }
  return undefined;
}

void Scorecard::AddStageTimes(const FrameWarp& w) {
  for (const auto& st : w.stage_ms) {
    auto it = std::find_if(stages_.begin(), stages_.end(),
                           [&](const auto& e) { return e.first == st.first; });
    if (it == stages_.end()) {
      stages_.push_back({st.first, {}});
      it = stages_.end() - 1;
    }
    it->second.push_back(st.second);
  }
}

std::vector<Eigen::Vector2d> Scorecard::LongestFiniteRun(const std::vector<Eigen::Vector2d>& x) {
  const auto run = LongestRun(x.size(), [&x](size_t i) { return x[i].allFinite(); });
  return std::vector<Eigen::Vector2d>(x.begin() + run.first, x.begin() + run.second);
}

Score Scorecard::Compute() const {
  Score sc;
  sc.frames = static_cast<int>(samples_.size());
  if (sc.frames == 0) return sc;
  const double fps = sim_.options().fps;
  const bool pose = !identity_;
  const double out_w = identity_ ? sim_.intrinsics().width : output_.width();
  const double out_h = identity_ ? sim_.intrinsics().height : output_.height();
  const double diag = std::hypot(out_w, out_h);
  // Jitter needs a contiguous series: each trajectory is scored on its
  // longest run of finite samples.
  const std::vector<Eigen::Vector2d> head = LongestFiniteRun(head_out_);
  sc.head_jitter_px = HighPassRms(head, fps, options_.highpass_hz);
  sc.head_jitter_frac = sc.head_jitter_px / diag;
  sc.head_stability = Stability(head);
  const size_t min_run = static_cast<size_t>(std::max(16.0, fps));  // >= 1 s
  ComputeBackground(fps, min_run, diag, &sc);
  ComputeMeshFigures(fps, &sc);
  ComputeCrop(pose, &sc);
  ComputeRotationError(&sc);
  ComputeBackgroundSteps(&sc);
  ComputeWindow(fps, &sc);
  auto rms_deg = [](const std::vector<double>& x) {
    double s2 = 0.0;
    for (double v : x) s2 += v * v;
    return x.empty() ? NAN : std::sqrt(s2 / x.size()) * 180.0 / M_PI;
  };
  if (output_roll_.size() == samples_.size()) sc.output_roll_rms_deg = rms_deg(output_roll_);
  sc.input_roll_rms_deg = rms_deg(input_roll_);
  sc.distortion = *std::min_element(distortion_.begin(), distortion_.end());
  sc.undefined_fraction = static_cast<double>(undefined_) / sc.frames;
  for (const auto& st : stages_) {
    sc.stage_ms.push_back({st.first, {Percentile(st.second, 0.5), Percentile(st.second, 0.99)}});
  }
  return sc;
}

void Scorecard::ComputeCrop(bool pose, Score* sc) const {
  if (!pose) return;  // the input, uncropped
  double area = 0.0, sum = 0.0, accel2 = 0.0;
  sc->kept_width_min = 1.0;
  for (size_t i = 0; i < kept_width_.size(); ++i) {
    const double k = kept_width_[i];
    area += k * k;
    sum += k;
    sc->kept_width_min = std::min(sc->kept_width_min, k);
    if (i >= 1) {
      sc->kept_width_max_step = std::max(sc->kept_width_max_step, std::abs(k - kept_width_[i - 1]));
    }
    if (i >= 2) accel2 += std::pow(k - 2.0 * kept_width_[i - 1] + kept_width_[i - 2], 2.0);
  }
  const double n = static_cast<double>(kept_width_.size());
  sc->cropping = area / n;
  sc->kept_width_mean = sum / n;
  sc->kept_width_rms_accel = n > 2 ? std::sqrt(accel2 / (n - 2)) : 0.0;
}

void Scorecard::ComputeBackground(double fps, size_t min_run, double diag, Score* out) const {
  // The far background's jitter and stability, the head relative to it,
  // and the visible background's jitter.
  Score& sc = *out;
  double bg = 0.0, bg_stab = 0.0;
  int nbg = 0;
  for (const auto& traj : background_out_) {
    const std::vector<Eigen::Vector2d> r = LongestFiniteRun(traj);
    if (r.size() < min_run) continue;
    bg += HighPassRms(r, fps, options_.highpass_hz);
    bg_stab += Stability(r);
    ++nbg;
  }
  sc.background_jitter_px = nbg ? bg / nbg : NAN;
  // Head relative to each background point, on the longest run of frames
  // where both are in view.
  double rel_sum = 0.0, floor_sum = 0.0;
  int nrel = 0;
  for (const auto& traj : background_out_) {
    const auto run = LongestRun(std::min(traj.size(), head_out_.size()), [&](size_t i) {
      return traj[i].allFinite() && head_out_[i].allFinite();
    });
    if (run.second - run.first < min_run) continue;
    std::vector<Eigen::Vector2d> h, d;
    for (size_t i = run.first; i < run.second; ++i) {
      h.push_back(head_out_[i]);
      d.push_back(head_out_[i] - traj[i]);
    }
    const double j_rel = HighPassRms(d, fps, options_.highpass_hz);
    rel_sum += j_rel;
    floor_sum += std::max(0.0, j_rel - HighPassRms(h, fps, options_.highpass_hz));
    ++nrel;
  }
  sc.relative_jitter_px = nrel ? rel_sum / nrel : NAN;
  sc.background_floor_px = nrel ? floor_sum / nrel : NAN;
  sc.background_jitter_frac = sc.background_jitter_px / diag;
  sc.background_stability = nbg ? bg_stab / nbg : NAN;
  double vis = 0.0;
  int nvis = 0;
  for (const auto& traj : visible_out_) {
    const std::vector<Eigen::Vector2d> r = LongestFiniteRun(traj);
    if (r.size() < min_run) continue;
    vis += HighPassRms(r, fps, options_.highpass_hz);
    ++nvis;
  }
  sc.visible_background_jitter_px = nvis ? vis / nvis : NAN;
}

void Scorecard::ComputeMeshFigures(double fps, Score* out) const {
  // Lines, cells, the band's jitter, and the largest per-frame steps.
  Score& sc = *out;
  sc.line_deviation_px = line_dev_;
  sc.line_deviation_frame = line_dev_frame_;
  sc.min_cell_ratio = min_ratio_;
  if (!cell_ratios_.empty()) sc.p01_cell_ratio = Percentile(cell_ratios_, 0.01);
  sc.folded_cells = folded_;
  sc.min_cell_ratio_frame = min_ratio_frame_;
  double band = 0.0;
  int nband = 0;
  for (size_t k = 0; k < band_offsets_.size(); ++k) {
    if (2 * band_frames_[k] < static_cast<int>(band_offsets_[k].size())) continue;
    band += HighPassRms(band_offsets_[k], fps, options_.highpass_hz);
    ++nband;
  }
  sc.band_jitter_px = nband ? band / nband : NAN;
  if (!line_devs_.empty()) sc.line_deviation_p99_px = Percentile(line_devs_, 0.99);
  if (!band_offsets_.empty()) {
    sc.blend_max_step_px = 0.0;
    sc.blend_max_accel_px = 0.0;
    for (const auto& traj : band_offsets_) LargestSteps(traj, &sc.blend_max_step_px, &sc.blend_max_accel_px);
  }
  double head_step = 0.0, head_accel = 0.0;
  if (LargestSteps(head_out_, &head_step, &head_accel)) {
    sc.head_max_step_px = head_step;
    sc.head_max_accel_px = head_accel;
  }
  double step = 0.0, accel = 0.0;
  if (LargestSteps(head_target_out_, &step, &accel)) {
    sc.head_target_max_step_px = step;
    sc.head_target_max_accel_px = accel;
  }
}

}  // namespace eval
}  // namespace steadiface
