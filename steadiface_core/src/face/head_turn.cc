// The turned head's axis and yaw from its region's flow (face/head_turn.h).
#include "steadiface_core/face/head_turn.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace steadiface {

Eigen::Vector2d HeadTurn::FaceCentre() const {
  return Eigen::Vector2d(axis_px.x() - radius_px * std::sin(yaw), axis_px.y());
}

bool UpdateHeadTurn(const RegionFlow& flow, HeadTurn* head) {
  const size_t all = std::min(flow.from.size(), flow.shift.size());
  const double r = head->radius_px;
  if (!(r > 0.0)) return false;
  // The tracks on the cylinder (within 0.9 radii of the axis: the rest may
  // be background beside the head), and each one's depth towards the
  // camera from its offset to the axis.
  std::vector<double> z, dx;
  double dy_mean = 0.0;
  for (size_t i = 0; i < all; ++i) {
    const double s = std::abs(flow.from[i].x() - head->axis_px.x()) / r;
    if (s > 0.9) continue;
    z.push_back(r * std::sqrt(1.0 - s * s));
    dx.push_back(flow.shift[i].x());
    dy_mean += flow.shift[i].y();
  }
  const size_t n = z.size();
  if (n < 3) return false;
  double z_mean = 0.0, dx_mean = 0.0;
  for (size_t i = 0; i < n; ++i) {
    z_mean += z[i];
    dx_mean += dx[i];
  }
  z_mean /= n;
  dx_mean /= n;
  dy_mean /= n;
  double var = 0.0, cov = 0.0;
  for (size_t i = 0; i < n; ++i) {
    var += (z[i] - z_mean) * (z[i] - z_mean);
    cov += (z[i] - z_mean) * (dx[i] - dx_mean);
  }
  var /= n;
  cov /= n;
  // dx = d_axis - z d_yaw. The rate is predicted unchanged, its variance
  // grown; the depths must spread by a twentieth of the radius for a
  // measurement, which enters by its standard error.
  head->yaw_rate_var += kHeadTurnRateProcessSd * kHeadTurnRateProcessSd;
  if (var > (0.05 * r) * (0.05 * r) && n > 3) {
    const double slope = cov / var;
    double residual = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double e = (dx[i] - dx_mean) - slope * (z[i] - z_mean);
      residual += e * e;
    }
    residual = std::max(residual / (n - 2), kHeadTurnFlowSdFloor * kHeadTurnFlowSdFloor);
    const double measured = ClipTurnRate(-slope);
    const double measured_var = residual / (n * var);
    const double gain = head->yaw_rate_var / (head->yaw_rate_var + measured_var);
    head->yaw_rate += gain * (measured - head->yaw_rate);
    head->yaw_rate_var *= 1.0 - gain;
  }
  const double d_yaw = head->yaw_rate;
  const double d_axis = dx_mean + d_yaw * z_mean;
  if (!std::isfinite(d_axis) || !std::isfinite(dy_mean)) return false;
  head->axis_px += Eigen::Vector2d(d_axis, dy_mean);
  const double yaw = head->yaw + d_yaw;
  head->past_profile = head->past_profile || std::abs(yaw) >= kHeadTurnMaxYaw;
  head->yaw = std::max(-kHeadTurnMaxYaw, std::min(kHeadTurnMaxYaw, yaw));
  return true;
}

}  // namespace steadiface
