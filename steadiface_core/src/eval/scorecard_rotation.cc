// The scorecard's rotation figures: the rotation the stabilizer used
// against the truth, the visible background's largest jump, and a window
// of the sequence (an IMU dropout) scored on its own with its hand-overs.
#include <algorithm>
#include <cmath>

#include "steadiface_core/common/high_pass_rms.h"
#include "steadiface_core/common/percentile.h"
#include "steadiface_core/eval/scorecard.h"
#include "eval/longest_run.h"

namespace steadiface {
namespace eval {
namespace {

double Angle(const Eigen::Quaterniond& q) { return Eigen::AngleAxisd(q.normalized()).angle(); }

// RMS over `window` of the high-passed longest finite run of `traj`, and
// how many window frames it covered; 0 covered when the run is shorter
// than `min_run`.
double WindowRms(const std::vector<Eigen::Vector2d>& traj, const std::vector<bool>& window,
                 double fps, double cutoff_hz, size_t min_run, int* covered) {
  *covered = 0;
  const auto longest = LongestRun(traj.size(), [&traj](size_t i) { return traj[i].allFinite(); });
  const size_t best_first = longest.first, best_len = longest.second - longest.first;
  if (best_len < min_run) return 0.0;
  const std::vector<Eigen::Vector2d> run(traj.begin() + best_first,
                                         traj.begin() + best_first + best_len);
  const std::vector<Eigen::Vector2d> h = HighPass(run, fps, cutoff_hz);
  double sum = 0.0;
  for (size_t k = 0; k < h.size(); ++k) {
    if (best_first + k < window.size() && window[best_first + k]) {
      sum += h[k].squaredNorm();
      ++*covered;
    }
  }
  return *covered ? std::sqrt(sum / *covered) : 0.0;
}

}  // namespace

void Scorecard::AddRotation(const sim::SimTruth& truth, const FrameWarp& w) {
  if (w.kind == FrameWarp::Kind::kIdentity || w.kind == FrameWarp::Kind::kHomography ||
      w.rows.empty()) {
    return;
  }
  const double mid = 0.5 * (sim_.intrinsics().height - 1);
  const double t = ToSeconds(sim_.timing().RowTime(truth.stamp, mid));
  true_middle_.push_back(sim_.CameraPose(t).R.conjugate());
  used_middle_.push_back(w.rows.Middle());
  // The virtual camera: the pose's, or the scene layer's (kMesh).
  virtual_.push_back(w.kind == FrameWarp::Kind::kMesh ? w.R_b : w.R_v);
}

void Scorecard::ComputeRotationError(Score* sc) const {
  const size_t n = true_middle_.size();
  if (n < 2 || n != samples_.size()) return;
  double sum = 0.0, worst = 0.0;
  for (size_t i = 1; i < n; ++i) {
    // The camera's turn from frame i-1 to frame i, in the camera: true and used.
    const Eigen::Quaterniond d_true = true_middle_[i] * true_middle_[i - 1].conjugate();
    const Eigen::Quaterniond d_used = used_middle_[i] * used_middle_[i - 1].conjugate();
    const double e = Angle(d_used.conjugate() * d_true);
    sum += e * e;
    worst = std::max(worst, e);
  }
  const double rms = std::sqrt(sum / (n - 1));
  sc->rotation_error_deg = rms * 180.0 / M_PI;
  sc->rotation_error_max_deg = worst * 180.0 / M_PI;
  sc->rotation_error_px = rms * model_.real_focal() * model_.intrinsics().width;
}

void Scorecard::ComputeBackgroundSteps(Score* sc) const {
  double worst = NAN;
  for (size_t i = 1; i < samples_.size(); ++i) {
    std::vector<double> steps;
    for (const auto& traj : visible_out_) {
      if (i < traj.size() && traj[i].allFinite() && traj[i - 1].allFinite()) {
        steps.push_back((traj[i] - traj[i - 1]).norm());
      }
    }
    if (steps.empty()) continue;
    const double median = Percentile(steps, 0.5);
    if (!(worst >= median)) worst = median;
  }
  sc->visible_background_max_step_px = worst;
}

void Scorecard::ComputeWindow(double fps, Score* sc) const {
  const double a = options_.window_start_s, b = options_.window_end_s;
  if (!(std::isfinite(a) && std::isfinite(b) && b > a) || samples_.empty()) return;
  std::vector<bool> window(samples_.size());
  for (size_t i = 0; i < samples_.size(); ++i) {
    window[i] = samples_[i].t >= a && samples_[i].t < b;
  }
  const size_t min_run = static_cast<size_t>(std::max(16.0, fps));
  int covered = 0;
  const double head = WindowRms(head_out_, window, fps, options_.highpass_hz, min_run, &covered);
  if (covered > 0) sc->window_head_jitter_px = head;
  double vis = 0.0;
  int nvis = 0;
  for (const auto& traj : visible_out_) {
    const double r = WindowRms(traj, window, fps, options_.highpass_hz, min_run, &covered);
    if (covered == 0) continue;
    vis += r;
    ++nvis;
  }
  if (nvis) sc->window_background_jitter_px = vis / nvis;
  if (virtual_.size() != samples_.size()) return;
  // The virtual pose's steps: at the hand-overs (within edge_s after each
  // edge), and elsewhere.
  const double f_out = output_.VirtualIntrinsics(Eigen::Vector2d::Zero()).fx;
  double at_start = 0.0, at_end = 0.0;
  std::vector<double> elsewhere;
  for (size_t i = 1; i < virtual_.size(); ++i) {
    const double step = f_out * Angle(virtual_[i] * virtual_[i - 1].conjugate());
    const double t = samples_[i].t;
    if (t >= a && t < a + options_.edge_s) {
      at_start = std::max(at_start, step);
    } else if (t >= b && t < b + options_.edge_s) {
      at_end = std::max(at_end, step);
    } else {
      elsewhere.push_back(step);
    }
  }
  sc->window_start_step_px = at_start;
  sc->window_end_step_px = at_end;
  if (!elsewhere.empty()) sc->virtual_step_p95_px = Percentile(elsewhere, 0.95);
}

}  // namespace eval
}  // namespace steadiface
