// Rows split into a fixed number of stripes, run with cv::parallel_for_
// (the warp's thread setting): each stripe keeps its own sums, added in
// stripe order afterwards, so the result does not depend on the threads.
#pragma once

#include <algorithm>

#include <opencv2/core.hpp>

namespace steadiface {
namespace composite_internal {

/// Stripes per call: enough to balance two to eight cores [-].
constexpr int kRowStripes = 16;

/// Calls body(stripe, first_row, end_row) for each of kRowStripes stripes
/// of rows [0, rows), in parallel; body may write only its stripe's rows
/// and its stripe's slot of any sums.
template <typename Body>
void ForRowStripes(int rows, const Body& body) {
  if (rows <= 0) return;
  const int stripes = std::min(kRowStripes, rows);
  cv::parallel_for_(cv::Range(0, stripes), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      body(k, static_cast<int>(static_cast<long long>(rows) * k / stripes),
           static_cast<int>(static_cast<long long>(rows) * (k + 1) / stripes));
    }
  });
}

}  // namespace composite_internal
}  // namespace steadiface
