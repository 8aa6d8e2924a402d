#pragma once

// Landmark-shape helpers the face tracker's files share (private to
// src/face/).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/common/stopwatch.h"

namespace steadiface {
namespace face_internal {

using Clock = std::chrono::steady_clock;
using ::steadiface::MsSince;

inline Eigen::Vector2d Mean(const std::vector<Eigen::Vector2d>& p) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& q : p) c += q;
  return c / static_cast<double>(std::max<size_t>(1, p.size()));
}

inline double RmsRadius(const std::vector<Eigen::Vector2d>& p, const Eigen::Vector2d& c) {
  double s = 0.0;
  for (const auto& q : p) s += (q - c).squaredNorm();
  return std::sqrt(s / std::max<size_t>(1, p.size()));
}

// Centred, unit-RMS shape.
inline std::vector<Eigen::Vector2d> Normalize(const std::vector<Eigen::Vector2d>& p) {
  const Eigen::Vector2d c = Mean(p);
  const double s = std::max(RmsRadius(p, c), 1e-9);
  std::vector<Eigen::Vector2d> out;
  out.reserve(p.size());
  for (const auto& q : p) out.push_back((q - c) / s);
  return out;
}

// RMS residual after the best rotation of normalized shape a onto b.
inline double ProcrustesResidual(const std::vector<Eigen::Vector2d>& a,
                          const std::vector<Eigen::Vector2d>& b) {
  double dot = 0.0, cross = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    dot += a[i].dot(b[i]);
    cross += a[i].x() * b[i].y() - a[i].y() * b[i].x();
  }
  const double th = std::atan2(cross, dot);
  const Eigen::Rotation2Dd R(th);
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) s += (R * a[i] - b[i]).squaredNorm();
  return std::sqrt(s / std::max<size_t>(1, a.size()));
}

inline cv::Rect2d Extent(const std::vector<Eigen::Vector2d>& p) {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const auto& q : p) {
    x0 = std::min(x0, q.x());
    y0 = std::min(y0, q.y());
    x1 = std::max(x1, q.x());
    y1 = std::max(y1, q.y());
  }
  return cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
}

inline bool AllFinite(const std::vector<Eigen::Vector2d>& p) {
  for (const auto& q : p) {
    if (!q.allFinite()) return false;
  }
  return true;
}

}  // namespace face_internal
}  // namespace steadiface
