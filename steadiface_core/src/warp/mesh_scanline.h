#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/warp/warper.h"

namespace steadiface {

/// cv::remap's fixed point: 1/32 px (INTER_BITS = 5).
constexpr int kInterBits = 5;
constexpr int kInterTabSize = 1 << kInterBits;
/// Guard bits of the stepped coordinates (below the 1/32 px).
constexpr int kScanFrac = 10;
/// Source coordinates beyond this clamp (they sample the black border).
constexpr float kScanClamp = 16000.0f;

/// std::lround for a float, inline (libm's lroundf is a call, and the scan
/// set-up makes four per mesh cell and row): rounds half away from zero.
/// Exact for every finite float: below 2^62 in magnitude x - trunc(x) is
/// exact (Sterbenz for |x| >= 1, x itself below, 0 once floats are
/// integers); larger, infinite or NaN arguments (a one-pixel segment's
/// unused step can be any value) go to std::lround itself.
inline int64_t RoundHalfAwayFromZero(float x) {
  if (!(std::abs(x) < 4.0e18f)) return std::lround(x);
  const int64_t t = static_cast<int64_t>(x);  // toward zero
  const float d = x - static_cast<float>(t);
  return t + (d >= 0.5f ? 1 : 0) - (d <= -0.5f ? 1 : 0);
}

/// One mesh cell's stretch of one output row: pixels u0..u1 (inclusive),
/// whose source coordinates are linear in u.
struct ScanSegment {
  int u0 = 0;
  int u1 = -1;
  /// The whole stretch is in range: pixel u's source coordinate in 1/32 px
  /// is (X + (u - u0) DX) >> kScanFrac (same for Y), exactly.
  bool stepped = false;
  int32_t X = 0, Y = 0, DX = 0, DY = 0;
  /// Otherwise: pixel u samples cvRound(clamp(x0 + dx (u - u0)) * 32)
  /// (same for y) [px].
  float x0 = 0.0f, y0 = 0.0f, dx = 0.0f, dy = 0.0f;
};

/// Calls f(const ScanSegment&) for each mesh cell of output row v (of an
/// output `width` px wide), left to right. `line` is scratch. Both the
/// Warper's dense maps and SampleMesh walk the mesh through this one
/// function, so they sample the same coordinates.
template <class F>
void ForEachScanSegment(const WarpMesh& m, int width, int v,
                        std::vector<Eigen::Vector2f>* line, F&& f) {
  line->resize(m.cols);
  // Cell row and weight.
  int j = 0;
  while (j + 1 < m.rows - 1 && m.v[j + 1] < v) ++j;
  const double span_v = m.v[j + 1] - m.v[j];
  const float b = span_v > 0 ? static_cast<float>((v - m.v[j]) / span_v) : 0.0f;
  const Eigen::Vector2f* top = &m.source[static_cast<size_t>(j) * m.cols];
  const Eigen::Vector2f* bot = top + m.cols;
  for (int i = 0; i < m.cols; ++i) {
    (*line)[i] = (1.0f - b) * top[i] + b * bot[i];
  }
  const int cells_x = m.cols - 1;
  for (int i = 0; i < cells_x; ++i) {
    ScanSegment s;
    s.u0 = static_cast<int>(std::ceil(m.u[i]));
    s.u1 = i + 1 == cells_x ? width - 1
                            : static_cast<int>(std::ceil(m.u[i + 1])) - 1;
    const double span_u = m.u[i + 1] - m.u[i];
    const float inv_span = static_cast<float>(span_u > 0 ? 1.0 / span_u : 0.0);
    const float offset = static_cast<float>(s.u0 - m.u[i]);
    const Eigen::Vector2f& l0 = (*line)[i];
    const Eigen::Vector2f& l1 = (*line)[i + 1];
    s.dx = (l1.x() - l0.x()) * inv_span;
    s.dy = (l1.y() - l0.y()) * inv_span;
    s.x0 = l0.x() + s.dx * offset;
    s.y0 = l0.y() + s.dy * offset;
    const float xe = s.x0 + s.dx * static_cast<float>(s.u1 - s.u0);
    const float ye = s.y0 + s.dy * static_cast<float>(s.u1 - s.u0);
    if (s.u1 >= s.u0 && std::abs(s.x0) < kScanClamp &&
        std::abs(s.y0) < kScanClamp && std::abs(xe) < kScanClamp &&
        std::abs(ye) < kScanClamp) {
      // The 1/32 px coordinates are linear in u, so step them in integer
      // fixed point (kScanFrac more fractional bits; the drift over a cell
      // of up to 128 px is <= 0.07 of a 1/32 px step): integer adds and
      // shifts instead of two float roundings per pixel.
      const float sc = static_cast<float>(kInterTabSize) *
                       static_cast<float>(1 << kScanFrac);
      s.stepped = true;
      s.X = static_cast<int32_t>(RoundHalfAwayFromZero(s.x0 * sc)) +
            (1 << (kScanFrac - 1));
      s.Y = static_cast<int32_t>(RoundHalfAwayFromZero(s.y0 * sc)) +
            (1 << (kScanFrac - 1));
      s.DX = static_cast<int32_t>(RoundHalfAwayFromZero(s.dx * sc));
      s.DY = static_cast<int32_t>(RoundHalfAwayFromZero(s.dy * sc));
    }
    f(s);
  }
}

/// The 1/32 px source coordinates of pixel u of an unstepped segment.
inline void ClampedScanCoordinates(const ScanSegment& s, int u, int32_t* X,
                                   int32_t* Y) {
  const float k = static_cast<float>(u - s.u0);
  const float px = std::min(std::max(s.x0 + s.dx * k, -kScanClamp), kScanClamp);
  const float py = std::min(std::max(s.y0 + s.dy * k, -kScanClamp), kScanClamp);
  *X = cvRound(px * static_cast<float>(kInterTabSize));
  *Y = cvRound(py * static_cast<float>(kInterTabSize));
}

}  // namespace steadiface
