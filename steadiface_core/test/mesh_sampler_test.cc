// The warp kernels' own tests: the scan set-up's rounding and the shuffle
// kernels against the portable one. (WarperTest.DirectSamplingIsRemapBitForBit
// ties the portable kernel to cv::remap through the Warper.)
#include "steadiface_core/warp/mesh_sampler.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "affine_mesh.h"
#include "steadiface_core/warp/warper.h"
#include "test_util.h"
#include "warp/mesh_scanline.h"

namespace steadiface {
namespace {

using testing_util::AffineMesh;
using testing_util::LoadImage;

// The scan set-up's inline rounding is std::lround's, on every float of
// a sweep of bit patterns (all exponents, both signs), the halves around
// each integer up to 2^24, and the neighbours of 0.5.
TEST(MeshSamplerTest, RoundHalfAwayFromZeroIsLround) {
  int checked = 0;
  for (uint32_t bits = 0; bits < 0xFF000000u; bits += 9973u) {
    float x;
    std::memcpy(&x, &bits, sizeof(x));
    if (!std::isfinite(x) || std::abs(x) >= 4.0e18f) continue;
    ASSERT_EQ(RoundHalfAwayFromZero(x), std::lround(x)) << x;
    ++checked;
  }
  for (int i = -(1 << 24); i <= (1 << 24); i += 257) {
    for (float x : {i + 0.5f, i - 0.5f, std::nextafter(i + 0.5f, 0.0f),
                    std::nextafter(i + 0.5f, 1e9f), std::nextafter(i - 0.5f, -1e9f)}) {
      ASSERT_EQ(RoundHalfAwayFromZero(x), std::lround(x)) << x;
      ++checked;
    }
  }
  EXPECT_EQ(RoundHalfAwayFromZero(std::nextafter(0.5f, 0.0f)), 0);
  EXPECT_EQ(RoundHalfAwayFromZero(0.5f), 1);
  EXPECT_EQ(RoundHalfAwayFromZero(-0.5f), -1);
  EXPECT_GT(checked, 400000);
}

// The shuffle kernels (one 16-byte load per source row for 4 bgr8 or 8
// mono8 output pixels, byte shuffles) against the portable kernel, which
// DirectSamplingIsRemapBitForBit ties to cv::remap: bit for bit on a real
// photo, over zooms in and out, rotations up to 30 degrees, a mirror, and
// offsets that run the groups off every edge of the input. Where they apply
// (zoom in, small rotation) they must sample most of the frame, or the
// speed they exist for is not there.
TEST(MeshSamplerTest, ShuffleKernelIsThePortableKernelBitForBit) {
  if (!ShuffleKernelAvailable()) GTEST_SKIP() << "no byte shuffle on this CPU";
  cv::Mat photo = LoadImage("leuvenA.jpg");
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(333, 251), cv::Size(7, 5)}) {
    cv::Mat bgr, grey;
    cv::resize(photo, bgr, size, 0, 0, cv::INTER_AREA);
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    for (const cv::Mat& input : {bgr, grey}) {
      int cases = 0;
      for (double scale : {0.7, 0.85, 1.0, 1.3, 2.5}) {
        for (double angle_deg : {0.0, 0.7, -3.0, 12.0, 30.0}) {
          for (bool mirror : {false, true}) {
            for (const Eigen::Vector2f& shift :
                 {Eigen::Vector2f(0, 0), Eigen::Vector2f(-0.3f * size.width, 0.2f * size.height),
                  Eigen::Vector2f(0.25f * size.width, -0.3f * size.height)}) {
              const float a = static_cast<float>(angle_deg * M_PI / 180.0);
              Eigen::Matrix2f A;
              A << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
              A *= static_cast<float>(scale);
              if (mirror) A.col(0) *= -1.0f;
              // Centre to centre, then the shift.
              const Eigen::Vector2f c_out(0.5f * size.width, 0.5f * size.height);
              const Eigen::Vector2f b = c_out - A * c_out + shift;
              const WarpMesh mesh = AffineMesh(size.width, size.height, 8, A, b);
              cv::Mat fast, portable;
              SampleStats st;
              SampleMesh(mesh, input, size.width, size.height, &fast, SampleKernel::kAuto, &st);
              SampleMesh(mesh, input, size.width, size.height, &portable,
                         SampleKernel::kPortable);
              ASSERT_EQ(cv::norm(fast, portable, cv::NORM_INF), 0.0)
                  << size << " channels " << input.channels() << " scale " << scale << " angle "
                  << angle_deg << " mirror " << mirror << " shift " << shift.transpose();
              const double px = static_cast<double>(size.area());
              if (size.width >= 333 && scale <= 0.85 && std::abs(angle_deg) <= 3.0 && !mirror &&
                  shift.isZero()) {
                // Zoom in, small rotation, no border: the case they are for.
                // A group of g pixels falls back when it crosses a source
                // row, for a share (g - 1) scale |sin(angle)| of groups;
                // 5 % more for the frame's edges.
                const int group = input.channels() == 3 ? 4 : 8;
                const double expected =
                    1.0 - (group - 1) * scale * std::abs(std::sin(a)) - 0.05;
                EXPECT_GE(st.shuffle_px, expected * px)
                    << size << " channels " << input.channels() << " scale " << scale
                    << " angle " << angle_deg;
                ++cases;
              }
              if (mirror || scale >= 2.5) EXPECT_EQ(st.shuffle_px, 0);  // never applies
            }
          }
        }
      }
      if (size.width >= 333) EXPECT_EQ(cases, 6);
    }
  }
  // 2 and 4 channels never take them.
  cv::Mat two, bgra;
  cv::Mat grey;
  cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
  cv::Mat planes[] = {grey, 255 - grey};
  cv::merge(planes, 2, two);
  cv::cvtColor(photo, bgra, cv::COLOR_BGR2BGRA);
  for (const cv::Mat& input : {two, bgra}) {
    const WarpMesh mesh =
        AffineMesh(input.cols, input.rows, 8, 0.8f * Eigen::Matrix2f::Identity(),
                   Eigen::Vector2f(0.1f * input.cols, 0.1f * input.rows));
    cv::Mat out;
    SampleStats st;
    SampleMesh(mesh, input, input.cols, input.rows, &out, SampleKernel::kAuto, &st);
    EXPECT_EQ(st.shuffle_px, 0) << input.channels();
  }
}

}  // namespace
}  // namespace steadiface
