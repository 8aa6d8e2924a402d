#pragma once

#include <opencv2/core.hpp>

namespace steadiface {

struct WarpMesh;

/// Renders `output` (width x height, the input's type) by sampling `input`
/// (8-bit, 1-4 channels) through the warp mesh directly: per output row and
/// mesh cell the source coordinate is linear in u, so it is stepped in
/// integer fixed point (1/32 px, 10 guard bits: the same coordinates as the
/// Warper's fixed-point maps) and sampled bilinearly, 4-8 pixels at a time
/// in OpenCV universal intrinsics (SSE/NEON), with no dense map in memory.
///
/// The arithmetic is cv::remap's (INTER_LINEAR, 5-bit fractions, weights
/// (32 - f) f products summing to 1024, rounded once), and outside the
/// input is black (BORDER_CONSTANT 0), so the output is bit-for-bit what
/// cv::remap gives with the same fixed-point maps. Deterministic: the result
/// does not depend on the thread count. Rows are split over OpenCV's
/// threads (cv::parallel_for_).
void SampleMesh(const WarpMesh& mesh, const cv::Mat& input, int width,
                int height, cv::Mat* output);

}  // namespace steadiface
