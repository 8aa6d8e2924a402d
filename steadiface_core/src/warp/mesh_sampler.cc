#include "steadiface_core/warp/mesh_sampler.h"

#include <atomic>
#include <cstdint>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "steadiface_core/warp/warper.h"
#include "warp/mesh_sampler_kernels.h"
#include "warp/mesh_sampler_shuffle.h"
#include "warp/mesh_scanline.h"

namespace steadiface {
namespace {

using namespace mesh_sampler_internal;  // NOLINT: this file's own kernels

#if CV_SIMD128
// A stepped 1-channel segment with the portable SIMD kernel, 8 pixels per
// group (groups that leave the image sampled per pixel). False when the
// segment is shorter than a group: the caller samples it per pixel.
bool Mono8SegmentPortable(const ScanSegment& seg, const cv::Mat& in, uchar* out,
                          SampleStats* counts) {
  const uchar* base = in.ptr<uchar>(0);
  const size_t step = in.step[0];
  const int max_iy = in.rows - 2;
  const cv::v_int32x4 ramp(0, seg.DX, 2 * seg.DX, 3 * seg.DX);
  const cv::v_int32x4 rampy(0, seg.DY, 2 * seg.DY, 3 * seg.DY);
  const cv::v_int32x4 dx4 = cv::v_setall_s32(4 * seg.DX);
  const cv::v_int32x4 dy4 = cv::v_setall_s32(4 * seg.DY);
  const int n = seg.u1 - seg.u0 + 1;
  // The whole segment inside: no per-group check.
  const bool inside = GroupInside(seg.X, seg.Y, seg.DX, seg.DY, n, in.cols - 2, max_iy);
  for (int g = 0; n >= 8 && g < n; g += 8) {
    // The last group overlaps the previous one rather than leave a
    // scalar tail (it rewrites the same values).
    if (g + 8 > n) g = n - 8;
    const int u = seg.u0 + g;
    const int32_t X = seg.X + g * seg.DX;
    const int32_t Y = seg.Y + g * seg.DY;
    if (!inside && !GroupInside(X, Y, seg.DX, seg.DY, 8, in.cols - 2, max_iy)) {
      SamplePixels(in, 1, X, Y, seg.DX, seg.DY, 8, out + u);
      counts->scalar_px += 8;
      continue;
    }
    const cv::v_int32x4 Xa = cv::v_setall_s32(X) + ramp;
    const cv::v_int32x4 Ya = cv::v_setall_s32(Y) + rampy;
    Mono8(base, step, Xa, Xa + dx4, Ya, Ya + dy4, out + u);
    counts->portable_simd_px += 8;
  }
  return n >= 8;
}

// The same for 3- and 4-channel segments, 4 pixels per group.
bool ColorSegmentPortable(const ScanSegment& seg, const cv::Mat& in, int cn, int width,
                          uchar* out, SampleStats* counts) {
  const uchar* base = in.ptr<uchar>(0);
  const size_t step = in.step[0];
  const int max_iy = in.rows - 2;
  const cv::v_int32x4 ramp(0, seg.DX, 2 * seg.DX, 3 * seg.DX);
  const cv::v_int32x4 rampy(0, seg.DY, 2 * seg.DY, 3 * seg.DY);
  // The 8-byte read of a 3-channel pixel ends two bytes past its right
  // neighbour: keep one more column of margin there.
  const int max_ix = cn == 3 ? in.cols - 3 : in.cols - 2;
  const int n = seg.u1 - seg.u0 + 1;
  const bool inside = GroupInside(seg.X, seg.Y, seg.DX, seg.DY, n, max_ix, max_iy);
  for (int g = 0; n >= 4 && g < n; g += 4) {
    if (g + 4 > n) g = n - 4;  // overlapping last group, as above
    const int u = seg.u0 + g;
    const int32_t X = seg.X + g * seg.DX;
    const int32_t Y = seg.Y + g * seg.DY;
    if (!inside && !GroupInside(X, Y, seg.DX, seg.DY, 4, max_ix, max_iy)) {
      SamplePixels(in, cn, X, Y, seg.DX, seg.DY, 4, out + u * cn);
      counts->scalar_px += 4;
      continue;
    }
    counts->portable_simd_px += 4;
    const cv::v_int32x4 Xv = cv::v_setall_s32(X) + ramp;
    const cv::v_int32x4 Yv = cv::v_setall_s32(Y) + rampy;
    if (cn == 3) {
      Color4<3>(base, step, Xv, Yv, u + 6 <= width, out + u * 3);
    } else {
      Color4<4>(base, step, Xv, Yv, false, out + u * 4);
    }
  }
  return n >= 4;
}
#endif  // CV_SIMD128

// One output row. `shuffle`: 1- and 3-channel stepped segments go through
// the shuffle kernels (only where ShuffleSupported()).
void SampleRow(const WarpMesh& m, const cv::Mat& in, int width, int v,
               bool shuffle, std::vector<Eigen::Vector2f>* line, uchar* out,
               SampleStats* counts) {
  const int cn = in.channels();
  (void)shuffle;
  ForEachScanSegment(m, width, v, line, [&](const ScanSegment& seg) {
    if (!seg.stepped) {
      for (int u = seg.u0; u <= seg.u1; ++u) {
        int32_t X, Y;
        ClampedScanCoordinates(seg, u, &X, &Y);
        SamplePixel(in, cn, X, Y, out + u * cn);
      }
      counts->scalar_px += seg.u1 - seg.u0 + 1;
      return;
    }
#ifdef STEADIFACE_SHUFFLE_KERNEL
    if (shuffle && cn == 3) {
      Color3SegmentShuffle(seg, in, width, out, counts);
      return;
    }
    if (shuffle && cn == 1) {
      Mono8SegmentShuffle(seg, in, out, counts);
      return;
    }
#endif
#if CV_SIMD128
    if (cn == 1 && Mono8SegmentPortable(seg, in, out, counts)) return;
    if ((cn == 3 || cn == 4) && ColorSegmentPortable(seg, in, cn, width, out, counts)) return;
#endif  // CV_SIMD128
    // Too short for a group, or no SIMD: per pixel.
    counts->scalar_px += seg.u1 - seg.u0 + 1;
    SamplePixels(in, cn, seg.X, seg.Y, seg.DX, seg.DY, seg.u1 - seg.u0 + 1, out + seg.u0 * cn);
  });
}

}  // namespace

bool ShuffleKernelAvailable() {
  // Asked once: the answer does not change while the process runs.
  static const bool available = ShuffleSupported();
  return available;
}

void SampleMesh(const WarpMesh& mesh, const cv::Mat& input, int width,
                int height, cv::Mat* output, SampleKernel kernel,
                SampleStats* stats) {
  output->create(height, width, input.type());
  cv::Mat& out = *output;
  const bool shuffle =
      kernel == SampleKernel::kAuto && ShuffleKernelAvailable();
  std::atomic<int64_t> shuffle_px{0}, simd_px{0}, scalar_px{0};
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    std::vector<Eigen::Vector2f> line;
    SampleStats counts;
    for (int v = range.start; v < range.end; ++v) {
      SampleRow(mesh, input, width, v, shuffle, &line, out.ptr<uchar>(v),
                &counts);
    }
    shuffle_px += counts.shuffle_px;
    simd_px += counts.portable_simd_px;
    scalar_px += counts.scalar_px;
  });
  if (stats != nullptr) {
    stats->shuffle_px = shuffle_px;
    stats->portable_simd_px = simd_px;
    stats->scalar_px = scalar_px;
  }
}

}  // namespace steadiface
