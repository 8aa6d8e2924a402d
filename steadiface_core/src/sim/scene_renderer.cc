#include "steadiface_core/sim/scene_renderer.h"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/sim/head_relief.h"

namespace steadiface {
namespace sim {

Eigen::Vector3d Billboard::WorldPoint(const Eigen::Vector2d& uv, double t) const {
  const Pose P = pose(t);
  const Eigen::Vector2d local = (uv - anchor_px) * metres_per_px;
  const double z = depth_m.empty() ? 0.0 : ReliefDepth(depth_m, uv);
  return P.R * Eigen::Vector3d(local.x(), local.y(), z) + P.p;
}

Billboard MakeFaceBillboard(const cv::Mat& photo, const cv::Rect& region,
                            double width_m, double feather) {
  Billboard b;
  const cv::Rect r = region & cv::Rect(0, 0, photo.cols, photo.rows);
  cv::Mat crop = photo(r).clone();
  cv::cvtColor(crop, b.bgra, cv::COLOR_BGR2BGRA);
  const double cx = 0.5 * (r.width - 1), cy = 0.5 * (r.height - 1);
  const double ax = 0.5 * r.width, ay = 0.5 * r.height;
  for (int y = 0; y < r.height; ++y) {
    cv::Vec4b* row = b.bgra.ptr<cv::Vec4b>(y);
    for (int x = 0; x < r.width; ++x) {
      const double d = std::hypot((x - cx) / ax, (y - cy) / ay);  // 1 on the ellipse
      const double a = std::min(1.0, std::max(0.0, (1.0 - d) / feather));
      row[x][3] = static_cast<uchar>(std::lround(255.0 * a));
    }
  }
  b.metres_per_px = width_m / r.width;
  b.anchor_px = Eigen::Vector2d(cx, cy);
  return b;
}

namespace {

// One billboard's texture sampled at every image pixel (BGRA; alpha 0 off
// the board), each band of rows with its own poses.
void RenderBoard(const CameraIntrinsics& k, const std::function<double(double)>& row_time,
                 const std::function<Pose(double)>& camera_pose, const Billboard* b, int band,
                 cv::Mat* layer) {
  if (!b->depth_m.empty()) {
    RenderRelief(k, row_time, camera_pose, *b, band, layer);
    return;
  }
  const Eigen::Matrix3d K =
      (Eigen::Matrix3d() << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1).finished();
  cv::Mat map_x(k.height, k.width, CV_32FC1), map_y(k.height, k.width, CV_32FC1);
  for (int y0 = 0; y0 < k.height; y0 += band) {
    const int y1 = std::min(k.height, y0 + band);
    const double t = row_time(0.5 * (y0 + y1 - 1));
    const Pose C = camera_pose(t);
    const Pose P = b->pose(t);
    // texture (u, v, 1) -> image, through the plane.
    const Eigen::Matrix3d Rcw = C.R.conjugate().toRotationMatrix();
    const Eigen::Matrix3d Rh = P.R.toRotationMatrix();
    const double s = b->metres_per_px;
    Eigen::Matrix3d A;
    A.col(0) = s * Rh.col(0);
    A.col(1) = s * Rh.col(1);
    A.col(2) = P.p - C.p - s * (Rh.col(0) * b->anchor_px.x() + Rh.col(1) * b->anchor_px.y());
    const Eigen::Matrix3d H = K * Rcw * A;
    const Eigen::Matrix3d G = H.inverse();
    for (int y = y0; y < y1; ++y) {
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      for (int x = 0; x < k.width; ++x) {
        const Eigen::Vector3d uvw = G * Eigen::Vector3d(x, y, 1.0);
        if (uvw.z() <= 1e-12) {  // behind the camera
          mx[x] = my[x] = -1e4f;
          continue;
        }
        mx[x] = static_cast<float>(uvw.x() / uvw.z());
        my[x] = static_cast<float>(uvw.y() / uvw.z());
      }
    }
  }
  cv::remap(b->bgra, *layer, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
}

}  // namespace

void RenderAlpha(const CameraIntrinsics& k, const std::function<double(double)>& row_time,
                 const std::function<Pose(double)>& camera_pose,
                 const std::vector<const Billboard*>& billboards, int band_rows, cv::Mat* out) {
  *out = cv::Mat(k.height, k.width, CV_8UC1, cv::Scalar(0));
  cv::Mat layer;
  for (const Billboard* b : billboards) {
    RenderBoard(k, row_time, camera_pose, b, std::max(1, band_rows), &layer);
    for (int y = 0; y < k.height; ++y) {
      const cv::Vec4b* src = layer.ptr<cv::Vec4b>(y);
      uchar* dst = out->ptr<uchar>(y);
      for (int x = 0; x < k.width; ++x) {
        const int a = src[x][3];
        dst[x] = static_cast<uchar>(a + (dst[x] * (255 - a) + 127) / 255);
      }
    }
  }
}

void RenderScene(const CameraIntrinsics& k,
                 const std::function<double(double)>& row_time,
                 const std::function<Pose(double)>& camera_pose,
                 const InfiniteBackground& background,
                 const std::vector<const Billboard*>& billboards, int band_rows,
                 cv::Mat* out) {
  const int band = std::max(1, band_rows);
  background.Render(k, [&](double y) {
    return camera_pose(row_time(y)).R.conjugate();  // world -> camera
  }, band, out);
  cv::Mat layer;
  for (const Billboard* b : billboards) {
    RenderBoard(k, row_time, camera_pose, b, band, &layer);
    for (int y = 0; y < k.height; ++y) {
      const cv::Vec4b* src = layer.ptr<cv::Vec4b>(y);
      cv::Vec3b* dst = out->ptr<cv::Vec3b>(y);
      for (int x = 0; x < k.width; ++x) {
        const int a = src[x][3];
        if (a == 0) continue;
        for (int c = 0; c < 3; ++c) {
          dst[x][c] = static_cast<uchar>((src[x][c] * a + dst[x][c] * (255 - a) + 127) / 255);
        }
      }
    }
  }
}

bool ProjectRollingShutter(const CameraIntrinsics& k,
                           const std::function<double(double)>& row_time,
                           const std::function<Pose(double)>& camera_pose,
                           const std::function<Eigen::Vector3d(double)>& point,
                           Eigen::Vector2d* pixel) {
  double y = 0.5 * (k.height - 1);
  Eigen::Vector2d px;
  for (int it = 0; it < 10; ++it) {
    const double t = row_time(y);
    const Pose C = camera_pose(t);
    const Eigen::Vector3d c = C.R.conjugate() * (point(t) - C.p);
    if (c.z() <= 1e-9) return false;
    px = Eigen::Vector2d(k.fx * c.x() / c.z() + k.cx, k.fy * c.y() / c.z() + k.cy);
    y = std::min(std::max(px.y(), 0.0), static_cast<double>(k.height - 1));
  }
  *pixel = px;
  return true;
}

}  // namespace sim
}  // namespace steadiface
