#include "steadiface_core/gyro/row_rotations.h"

#include <algorithm>
#include <cmath>

#include "steadiface_core/common/so3.h"

namespace steadiface {

RowRotations::RowRotations(const Eigen::Quaterniond& R_r, int height)
    : height_(std::max(1, height)), table_{R_r.normalized()} {}

QueryResult RowRotations::Build(const OrientationTimeline& timeline,
                                const RowTiming& timing, Time stamp,
                                int samples, RowRotations* out) {
  const int h = timing.height();
  const int n = std::max(1, std::min(samples, h));
  std::vector<Eigen::Quaterniond> table(n);
  for (int i = 0; i < n; ++i) {
    const double y = n > 1 ? static_cast<double>(i) * (h - 1) / (n - 1) : 0.5 * (h - 1);
    const QueryResult r =
        timeline.RealRotation(timing.RowTime(stamp, y), &table[i]);
    if (!QuerySucceeded(r)) return r;
    if (i > 0) table[i] = AlignSign(table[i], table[i - 1]);
  }
  out->height_ = h;
  out->table_ = std::move(table);
  return QueryResult::kOk;
}

RowRotations RowRotations::FromTable(std::vector<Eigen::Quaterniond> table,
                                     int height) {
  RowRotations r;
  r.height_ = std::max(1, height);
  for (size_t i = 0; i < table.size(); ++i) {
    table[i].normalize();
    if (i > 0) table[i] = AlignSign(table[i], table[i - 1]);
  }
  r.table_ = std::move(table);
  return r;
}

Eigen::Quaterniond RowRotations::At(double y) const {
  if (table_.size() == 1) return table_[0];
  const double n1 = static_cast<double>(table_.size() - 1);
  if (!std::isfinite(y)) y = 0.5 * (height_ - 1);  // found by fuzz_imu
  double s = height_ > 1 ? y / (height_ - 1) * n1 : 0.0;
  s = std::min(std::max(s, 0.0), n1);
  const size_t i = std::min(static_cast<size_t>(s), table_.size() - 2);
  return table_[i].slerp(s - static_cast<double>(i), table_[i + 1]);
}

QueryResult RealRotationAtRow(const OrientationTimeline& timeline,
                              const RowTiming& timing, Time stamp, double y,
                              Eigen::Quaterniond* R_r) {
  return timeline.RealRotation(timing.RowTime(stamp, y), R_r);
}

}  // namespace steadiface
