#include "steadiface_core/sim/background.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace steadiface {
namespace sim {

InfiniteBackground::InfiniteBackground(const cv::Mat& photo, double focal_px)
    : photo_(photo), focal_px_(focal_px) {}

Eigen::Vector2d InfiniteBackground::TextureCoords(
    const Eigen::Vector3d& d) const {
  const double z = std::max(d.z(), 1e-6);
  return Eigen::Vector2d(0.5 * (photo_.cols - 1) + focal_px_ * d.x() / z,
                         0.5 * (photo_.rows - 1) + focal_px_ * d.y() / z);
}

void InfiniteBackground::Render(
    const CameraIntrinsics& k,
    const std::function<Eigen::Quaterniond(double)>& R_of_row, int band_rows,
    cv::Mat* out) const {
  cv::Mat map_x(k.height, k.width, CV_32FC1), map_y(k.height, k.width, CV_32FC1);
  const int band = std::max(1, band_rows);
  for (int y0 = 0; y0 < k.height; y0 += band) {
    const int y1 = std::min(k.height, y0 + band);
    const double ym = band == 1 ? y0 : 0.5 * (y0 + y1 - 1);
    const Eigen::Matrix3d Rt = R_of_row(ym).conjugate().toRotationMatrix();
    for (int y = y0; y < y1; ++y) {
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      for (int x = 0; x < k.width; ++x) {
        const Eigen::Vector3d ray((x - k.cx) / k.fx, (y - k.cy) / k.fy, 1.0);
        const Eigen::Vector2d tc = TextureCoords(Rt * ray);
        mx[x] = static_cast<float>(tc.x());
        my[x] = static_cast<float>(tc.y());
      }
    }
  }
  cv::remap(photo_, *out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
}

}  // namespace sim
}  // namespace steadiface
