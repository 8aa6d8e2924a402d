#include "steadiface_core/view/dynamic_crop.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace steadiface {
namespace {

constexpr size_t kMaxNeeds = 4096;

bool In(double v, double lo, double hi) {
  return std::isfinite(v) && v >= lo && v <= hi;
}

}  // namespace

Status ParseCropMode(const std::string& name, CropMode* mode) {
  if (name == "fixed") {
    *mode = CropMode::kFixed;
  } else if (name == "dynamic") {
    *mode = CropMode::kDynamic;
  } else {
    return Status::Error("output crop must be fixed or dynamic, got '" + name +
                         "'");
  }
  return Status::Ok();
}

const char* CropModeName(CropMode mode) {
  return mode == CropMode::kDynamic ? "dynamic" : "fixed";
}

Status ValidateDynamicCropOptions(const DynamicCropOptions& o) {
  std::ostringstream err;
  if (!In(o.widest_crop_ratio, 0.0, 0.4)) {
    err << "output.dynamic.widest_crop_ratio must be in [0, 0.4], got "
        << o.widest_crop_ratio;
  } else if (!In(o.headroom, 1.0, 10.0)) {
    err << "output.dynamic.headroom must be in [1, 10], got " << o.headroom;
  } else if (!In(o.extra, 0.0, 0.2)) {
    err << "output.dynamic.extra must be in [0, 0.2], got " << o.extra;
  } else if (!In(o.memory_s, 0.1, 30.0)) {
    err << "output.dynamic.memory must be in [0.1, 30] s, got " << o.memory_s;
  } else if (!In(o.max_widen_rate, 1e-4, 10.0) ||
             !In(o.max_tighten_rate, 1e-4, 10.0)) {
    err << "output.dynamic.max_widen_rate and max_tighten_rate must be in "
           "[1e-4, 10] per s, got "
        << o.max_widen_rate << " and " << o.max_tighten_rate;
  } else if (!In(o.max_widen_accel, 1e-5, 100.0) ||
             !In(o.max_tighten_accel, 1e-5, 100.0)) {
    err << "output.dynamic.max_widen_accel and max_tighten_accel must be in "
           "[1e-5, 100] per s^2, "
           "got "
        << o.max_widen_accel << " and " << o.max_tighten_accel;
  } else if (!In(o.shake_path_hz, 0.05, 10.0)) {
    err << "output.dynamic.shake_path_hz must be in [0.05, 10] Hz, got "
        << o.shake_path_hz;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

DynamicCrop::DynamicCrop(const DynamicCropOptions& options, double tightest)
    : options_(options),
      tightest_(tightest),
      widest_(std::min(options.widest_crop_ratio, tightest)),
      r_(options.mode == CropMode::kDynamic && options.start_wide ? widest_
                                                                  : tightest) {}

void DynamicCrop::Reset() {
  needs_.clear();
  has_time_ = false;
  rate_ = 0.0;
}

double DynamicCrop::Target(double t_s, double shake_need, double solved_need) {
  if (std::isfinite(shake_need) && std::isfinite(solved_need)) {
    needs_.push_back({t_s, shake_need, solved_need});
  }
  while (!needs_.empty() && (needs_.size() > kMaxNeeds ||
                             needs_.front().t_s < t_s - options_.memory_s)) {
    needs_.pop_front();
  }
  double shake = 0.0, solved = 0.0;
  for (const Need& n : needs_) {
    shake = std::max(shake, n.shake);
    solved = std::max(solved, n.solved);
  }
  // The shake is bursty: room for more than was seen. A solved pose at the
  // crop's edge (E_p holding it in) asks for `extra` more each frame until
  // it fits.
  const double target =
      std::max(options_.headroom * shake, solved) + options_.extra;
  return std::min(std::max(target, widest_), tightest_);
}

CropReport DynamicCrop::Update(double t_s, double shake_need,
                               double solved_need) {
  CropReport report;
  report.crop_ratio = r_;
  report.shake_need = shake_need;
  report.solved_need = solved_need;
  report.dynamic = options_.mode == CropMode::kDynamic;
  if (options_.mode == CropMode::kFixed || !std::isfinite(t_s)) {
    report.target = r_;
    return report;
  }
  report.target = Target(t_s, shake_need, solved_need);
  const double dt =
      has_time_ ? std::min(std::max(t_s - last_t_, 0.0), 0.5) : 0.0;
  has_time_ = true;
  last_t_ = t_s;
  if (!(dt > 0.0)) return report;
  // Towards the target with a bounded rate and rate change: the fastest
  // rate that can still stop at the target, reached by at most a dt per
  // frame (the widening's or the tightening's a).
  const double e = report.target - r_;
  // A tightening, until it has stopped, brakes as hard as it may start.
  const bool tighten = e > 0.0;
  const double a = tighten || rate_ > 0.0 ? options_.max_tighten_accel
                                          : options_.max_widen_accel;
  if (std::abs(e) <= a * dt * dt && std::abs(rate_) <= a * dt) {
    r_ = report.target;  // arrived: stop without chattering about it
    rate_ = 0.0;
    return report;
  }
  // The fastest rate from which steps slowing by a dt each stop within
  // |e|: v dt + (v - a dt) dt + ... = v^2 / (2 a) + v dt / 2 = |e|.
  const double v_max =
      tighten ? options_.max_tighten_rate : options_.max_widen_rate;
  const double v_stop =
      a * (std::sqrt(0.25 * dt * dt + 2.0 * std::abs(e) / a) - 0.5 * dt);
  const double v_want = std::copysign(std::min(v_max, v_stop), e);
  rate_ += std::min(std::max(v_want - rate_, -a * dt), a * dt);
  r_ += rate_ * dt;
  if (r_ >= tightest_ || r_ <= widest_) {
    r_ = std::min(std::max(r_, widest_), tightest_);
    rate_ = 0.0;
  }
  return report;
}

}  // namespace steadiface
