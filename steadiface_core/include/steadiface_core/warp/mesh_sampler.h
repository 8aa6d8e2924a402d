#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace steadiface {

struct WarpMesh;

/// Which kernel samples 1- and 3-channel input.
enum class SampleKernel {
  /// The shuffle kernels where the CPU has them (SSSE3 on x86, any
  /// AArch64), else the portable one. All give the same output bit for bit.
  kAuto,
  /// The portable universal-intrinsics kernel only (tests, benchmarks).
  kPortable,
};

/// How many output pixels each path sampled (a segment's overlapping last
/// group counts in full, so the sum can exceed width x height slightly).
struct SampleStats {
  /// Shuffle kernels: a group of 4 (3 channels) or 8 (1 channel) pixels
  /// from one 16-byte load per source row.
  int64_t shuffle_px = 0;
  /// Universal intrinsics, every pixel's neighbourhood loaded on its own.
  int64_t portable_simd_px = 0;
  /// One pixel at a time: groups at the input's edge, short segments,
  /// coordinates outside the stepping range, 2 channels.
  int64_t scalar_px = 0;
};

/// True when SampleKernel::kAuto runs the shuffle kernels (1 and 3
/// channels).
bool ShuffleKernelAvailable();

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
///
/// 3- and 1-channel input (bgr8, mono8) goes through shuffle kernels where
/// the CPU has them (`kernel`, ShuffleKernelAvailable()): 4 (bgr8) or 8
/// (mono8) output pixels that read one source row pair and one 16-byte span
/// of it take one load per row and byte shuffles instead of per-pixel
/// loads; same arithmetic, same output. `stats`, if given, receives the
/// pixel counts per path.
void SampleMesh(const WarpMesh& mesh, const cv::Mat& input, int width,
                int height, cv::Mat* output,
                SampleKernel kernel = SampleKernel::kAuto,
                SampleStats* stats = nullptr);

}  // namespace steadiface
