#include "steadiface_core/stabilizer/head_smoother.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace steadiface {

Status ValidateHeadSmootherOptions(const HeadSmootherOptions& o) {
  std::ostringstream err;
  if (!std::isfinite(o.w_stay) || o.w_stay < 0.0 || o.w_stay > 1e9) {
    err << "head.w_stay must be in [0, 1e9], got " << o.w_stay;
  } else if (!std::isfinite(o.w_follow) || o.w_follow < 0.0 ||
             o.w_follow > 1e9) {
    err << "head.w_follow must be in [0, 1e9], got " << o.w_follow;
  } else if (o.w_stay + o.w_follow <= 0.0) {
    err << "head.w_stay and head.w_follow cannot both be 0";
  } else if (!std::isfinite(o.d_ref) || o.d_ref <= 0.0 || o.d_ref > 1.0) {
    err << "head.d_ref must be in (0, 1] (fraction of width), got " << o.d_ref;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

double HeadSmoother::Objective(const Eigen::Vector2d& H,
                               const Eigen::Vector2d& previous,
                               const Eigen::Vector2d& centre) const {
  const Eigen::Vector2d d = (H - centre).cwiseAbs();
  const double m = std::max(d.x(), d.y()) / options_.d_ref;
  return options_.w_stay * (H - previous).squaredNorm() +
         options_.w_follow * m * m;
}

Eigen::Vector2d HeadSmoother::Solve(const Eigen::Vector2d& previous,
                                    const Eigen::Vector2d& centre,
                                    const Eigen::Vector2d& margin) const {
  const double w1 = options_.w_stay;
  const double k = options_.w_follow / (options_.d_ref * options_.d_ref);
  const Eigen::Vector2d a = previous - centre;
  const double abs_a[2] = {std::abs(a.x()), std::abs(a.y())};
  const double r[2] = {std::max(margin.x(), 0.0) * (1.0 - 1e-9),
                       std::max(margin.y(), 0.0) * (1.0 - 1e-9)};
  // D(m): clamp of a to the box min(m, r_i).
  auto d_of = [&](double m) {
    Eigen::Vector2d d;
    for (int i = 0; i < 2; ++i) {
      const double b = std::min(m, r[i]);
      d[i] = std::min(std::max(a[i], -b), b);
    }
    return d;
  };
  auto f_of = [&](double m) {
    const Eigen::Vector2d d = d_of(m);
    const double inf = std::max(std::abs(d.x()), std::abs(d.y()));
    return w1 * (d - a).squaredNorm() + k * inf * inf;
  };
  // Breakpoints of the piecewise quadratic in m.
  const double m_max = std::max(std::min(abs_a[0], r[0]), std::min(abs_a[1], r[1]));
  std::vector<double> bps = {0.0, m_max};
  for (int i = 0; i < 2; ++i) {
    if (abs_a[i] < m_max) bps.push_back(abs_a[i]);
    if (r[i] < m_max) bps.push_back(r[i]);
  }
  std::sort(bps.begin(), bps.end());
  double best_m = 0.0, best_f = std::numeric_limits<double>::infinity();
  for (size_t p = 0; p < bps.size(); ++p) {
    const double lo = bps[p];
    const double hi = p + 1 < bps.size() ? bps[p + 1] : bps[p];
    // Candidates: both ends, and the stationary point of the piece.
    // On (lo, hi) each axis is either "active" (|a_i| > m, m < r_i: d_i = m)
    // or fixed. f = w1 sum_active (|a_i| - m)^2 + const + k m^2 when the
    // infinity norm equals m (some axis active), so
    // m* = w1 sum_active |a_i| / (k + w1 n_active).
    const double mid = 0.5 * (lo + hi);
    double num = 0.0;
    int n_active = 0;
    for (int i = 0; i < 2; ++i) {
      if (abs_a[i] > mid && r[i] > mid) {
        num += abs_a[i];
        ++n_active;
      }
    }
    std::vector<double> cands = {lo, hi};
    if (n_active > 0) {
      cands.push_back(std::min(std::max(w1 * num / (k + w1 * n_active), lo), hi));
    }
    for (double m : cands) {
      const double f = f_of(m);
      if (f < best_f) {
        best_f = f;
        best_m = m;
      }
    }
  }
  return centre + d_of(best_m);
}

}  // namespace steadiface
