#include "steadiface_core/composite/layer_homography.h"

#include <algorithm>
#include <cmath>

namespace steadiface {

Eigen::Matrix3d PixelK(const CameraIntrinsics& k) {
  Eigen::Matrix3d K;
  K << k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0;
  return K;
}

LayerView OutputView(const OutputGeometry& output, const Eigen::Quaterniond& R_v,
                     const Eigen::Vector2d& t) {
  LayerView v;
  v.R = R_v.normalized();
  v.K = PixelK(output.VirtualIntrinsics(t));
  return v;
}

Eigen::Matrix3d HomographyBetween(const LayerView& to, const LayerView& from) {
  return to.K * (to.R * from.R.conjugate()).toRotationMatrix() * from.K.inverse();
}

cv::Matx33d RectMap(const Eigen::Matrix3d& H, const cv::Rect& src, double scale_src,
                    const cv::Rect& dst, double scale_dst) {
  // dst rect pixel d -> view pixel x = d / scale_dst + dst.tl (pixel centres
  // kept: (d + 0.5) / s - 0.5) -> H -> view pixel y -> src rect pixel.
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(0, 0) = D(1, 1) = 1.0 / scale_dst;
  D(0, 2) = 0.5 / scale_dst - 0.5 + dst.x;
  D(1, 2) = 0.5 / scale_dst - 0.5 + dst.y;
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = S(1, 1) = scale_src;
  S(0, 2) = (0.5 - src.x) * scale_src - 0.5;
  S(1, 2) = (0.5 - src.y) * scale_src - 0.5;
  const Eigen::Matrix3d M = S * H * D;
  cv::Matx33d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = M(r, c);
  }
  return m;
}

cv::Rect MapRect(const Eigen::Matrix3d& H, const cv::Rect& r, const cv::Rect& bounds) {
  if (r.empty()) return cv::Rect();
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector3d p((c & 1) ? r.x + r.width - 1 : r.x,
                            (c & 2) ? r.y + r.height - 1 : r.y, 1.0);
    const Eigen::Vector3d q = H * p;
    if (!(q.z() > 1e-9)) return cv::Rect();
    x0 = std::min(x0, q.x() / q.z());
    x1 = std::max(x1, q.x() / q.z());
    y0 = std::min(y0, q.y() / q.z());
    y1 = std::max(y1, q.y() / q.z());
  }
  if (!std::isfinite(x0 + x1 + y0 + y1)) return cv::Rect();
  const double lim = 1e7;
  const int ix0 = static_cast<int>(std::floor(std::max(-lim, x0))) - 1;
  const int iy0 = static_cast<int>(std::floor(std::max(-lim, y0))) - 1;
  const int ix1 = static_cast<int>(std::ceil(std::min(lim, x1))) + 2;
  const int iy1 = static_cast<int>(std::ceil(std::min(lim, y1))) + 2;
  return cv::Rect(ix0, iy0, ix1 - ix0, iy1 - iy0) & bounds;
}

}  // namespace steadiface
