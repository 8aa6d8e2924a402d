// The warp kernels on AArch64 (run under qemu-user by scripts/dev/check_aarch64,
// which cross-compiles this file with steadiface_core/src/warp/mesh_sampler.cc):
// the shuffle kernels (NEON tbl, umull + addp) against the portable
// universal-intrinsics kernel and against an independent scalar
// implementation of cv::remap's fixed-point bilinear arithmetic, bit for
// bit, for bgr8 and mono8 over zooms, rotations, a mirror and offsets that
// run off every edge. Exits non-zero on any difference, or if the shuffle
// kernels sampled less of the frame than the geometry allows where they
// apply (then the check would prove little).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "affine_mesh.h"
#include "steadiface_core/warp/mesh_sampler.h"
#include "steadiface_core/warp/warper.h"
#include "warp/mesh_scanline.h"

namespace {

using steadiface::WarpMesh;
using steadiface::testing_util::AffineMesh;

// cv::remap INTER_LINEAR with BORDER_CONSTANT 0 on 1/32 px coordinates,
// written out plainly: the coordinates come from the same scan segments.
void ReferenceSample(const WarpMesh& mesh, const cv::Mat& in, cv::Mat* out) {
  const int cn = in.channels();
  out->create(in.rows, in.cols, in.type());
  std::vector<Eigen::Vector2f> line;
  for (int v = 0; v < in.rows; ++v) {
    steadiface::ForEachScanSegment(
        mesh, in.cols, v, &line, [&](const steadiface::ScanSegment& s) {
          for (int u = s.u0; u <= s.u1; ++u) {
            int32_t X, Y;
            if (s.stepped) {
              X = (s.X + (u - s.u0) * s.DX) >> steadiface::kScanFrac;
              Y = (s.Y + (u - s.u0) * s.DY) >> steadiface::kScanFrac;
            } else {
              steadiface::ClampedScanCoordinates(s, u, &X, &Y);
            }
            const int ix = X >> 5, iy = Y >> 5, fx = X & 31, fy = Y & 31;
            const int w[4] = {(32 - fx) * (32 - fy), fx * (32 - fy),
                              (32 - fx) * fy, fx * fy};
            for (int c = 0; c < cn; ++c) {
              int sum = 0;
              for (int k = 0; k < 4; ++k) {
                const int x = ix + (k & 1), y = iy + (k >> 1);
                if (x >= 0 && y >= 0 && x < in.cols && y < in.rows) {
                  sum += in.ptr<uint8_t>(y)[x * cn + c] * w[k];
                }
              }
              out->ptr<uint8_t>(v)[u * cn + c] =
                  static_cast<uint8_t>((sum + 512) >> 10);
            }
          }
        });
  }
}

// What the cases found.
struct Tally {
  int cases = 0, failures = 0, applicable = 0;
  int64_t shuffle_px = 0, total_px = 0;
};

// Smooth structure plus noise: neighbouring bytes differ.
cv::Mat TestImage(const cv::Size& size, int cn, uint32_t* state) {
  cv::Mat img(size, CV_8UC(cn));
  for (int y = 0; y < img.rows; ++y) {
    uint8_t* p = img.ptr<uint8_t>(y);
    for (int x = 0; x < img.cols * cn; ++x) {
      *state = *state * 1664525u + 1013904223u;
      p[x] = static_cast<uint8_t>((x * 7 + y * 3) / 2 + ((*state >> 24) & 63));
    }
  }
  return img;
}

// One affine warp of `img`: the shuffle kernels (kAuto), the portable one
// and the reference must agree bit for bit; where the kernels apply, they
// must cover what the geometry allows.
void CheckCase(const cv::Mat& img, double scale, double angle_deg, bool mirror, float shift,
               Tally* t) {
  const cv::Size size = img.size();
  const int cn = img.channels();
  const float a = static_cast<float>(angle_deg * M_PI / 180.0);
  Eigen::Matrix2f A;
  A << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  A *= static_cast<float>(scale);
  if (mirror) A.col(0) *= -1.0f;
  const Eigen::Vector2f c(0.5f * size.width, 0.5f * size.height);
  const Eigen::Vector2f b = c - A * c + Eigen::Vector2f(shift * size.width, -shift * size.height);
  const WarpMesh mesh = AffineMesh(size.width, size.height, 8, A, b);
  cv::Mat fast, portable, reference;
  steadiface::SampleStats st;
  steadiface::SampleMesh(mesh, img, size.width, size.height, &fast,
                         steadiface::SampleKernel::kAuto, &st);
  steadiface::SampleMesh(mesh, img, size.width, size.height, &portable,
                         steadiface::SampleKernel::kPortable);
  ReferenceSample(mesh, img, &reference);
  if (cv::norm(fast, portable, cv::NORM_INF) != 0.0 ||
      cv::norm(fast, reference, cv::NORM_INF) != 0.0) {
    ++t->failures;
    std::printf("DIFFERENT: %dx%d channels %d scale %.2f angle %.1f mirror %d shift %.2f\n",
                size.width, size.height, cn, scale, angle_deg, mirror ? 1 : 0, shift);
  }
  t->shuffle_px += st.shuffle_px;
  t->total_px += size.area();
  ++t->cases;
  // Zoom in, small rotation, no border: the kernels' case. A group of g
  // pixels falls back when it crosses a source row, for (g - 1) scale
  // |sin(angle)| of groups; 5 % for the edges.
  if (size.width >= 320 && scale <= 0.85 && std::abs(angle_deg) <= 3.0 && !mirror &&
      shift == 0.0f) {
    const int group = cn == 3 ? 4 : 8;
    const double expected = 1.0 - (group - 1) * scale * std::abs(std::sin(a)) - 0.05;
    ++t->applicable;
    if (st.shuffle_px < expected * size.area()) {
      ++t->failures;
      std::printf("LOW COVERAGE: channels %d scale %.2f angle %.1f: %.3f < %.3f\n", cn, scale,
                  angle_deg, static_cast<double>(st.shuffle_px) / size.area(), expected);
    }
  }
}

}  // namespace

int main() {
  if (!steadiface::ShuffleKernelAvailable()) {
    std::printf("aarch64 check: the shuffle kernels are not built here\n");
    return 1;
  }
  uint32_t state = 12345;
  Tally t;
  for (const cv::Size size : {cv::Size(320, 240), cv::Size(97, 61)}) {
    for (int cn : {1, 3}) {
      const cv::Mat img = TestImage(size, cn, &state);
      for (double scale : {0.7, 0.85, 1.0, 1.3}) {
        for (double angle_deg : {0.0, 0.7, -3.0, 12.0}) {
          for (bool mirror : {false, true}) {
            for (float shift : {0.0f, -0.3f, 0.25f}) CheckCase(img, scale, angle_deg, mirror, shift, &t);
          }
        }
      }
    }
  }
  std::printf("aarch64 check: %d cases, %d failed (%d where the shuffle "
              "kernels apply); they took %.1f%% of all pixels\n",
              t.cases, t.failures, t.applicable, 100.0 * t.shuffle_px / t.total_px);
  return t.failures == 0 && t.applicable == 12 ? 0 : 1;
}
