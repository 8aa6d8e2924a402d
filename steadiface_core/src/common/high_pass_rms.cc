#include "steadiface_core/common/high_pass_rms.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace steadiface {

double HighPassRms(const std::vector<Eigen::Vector2d>& x, double fps,
                   double cutoff_hz) {
  const int n = static_cast<int>(x.size());
  if (n < 4) return 0.0;
  const std::vector<Eigen::Vector2d> h = HighPass(x, fps, cutoff_hz);
  double total = 0.0;  // axis by axis, as it always was summed
  for (int axis = 0; axis < 2; ++axis) {
    for (const Eigen::Vector2d& v : h) total += v[axis] * v[axis];
  }
  return std::sqrt(total / n);
}

std::vector<Eigen::Vector2d> HighPass(const std::vector<Eigen::Vector2d>& x,
                                      double fps, double cutoff_hz) {
  const int n = static_cast<int>(x.size());
  std::vector<Eigen::Vector2d> out(x.size(), Eigen::Vector2d::Zero());
  if (n < 4) return out;
  for (int axis = 0; axis < 2; ++axis) {
    // Remove the linear trend (least squares).
    double st = 0, sx = 0, stt = 0, stx = 0;
    for (int i = 0; i < n; ++i) {
      st += i;
      sx += x[i][axis];
      stt += double(i) * i;
      stx += i * x[i][axis];
    }
    const double b = (n * stx - st * sx) / (n * stt - st * st);
    const double a = (sx - b * st) / n;
    cv::Mat in(1, n, CV_64F), spec, back;
    for (int i = 0; i < n; ++i) in.at<double>(0, i) = x[i][axis] - (a + b * i);
    cv::dft(in, spec, cv::DFT_COMPLEX_OUTPUT);
    for (int k = 0; k < n; ++k) {
      const int kk = std::min(k, n - k);
      const double f = kk * fps / n;
      if (f < cutoff_hz) spec.at<cv::Vec2d>(0, k) = cv::Vec2d(0, 0);
    }
    cv::dft(spec, back, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
    for (int i = 0; i < n; ++i) out[i][axis] = back.at<double>(0, i);
  }
  return out;
}

}  // namespace steadiface
