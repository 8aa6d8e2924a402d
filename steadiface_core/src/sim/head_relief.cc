#include "steadiface_core/sim/head_relief.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Geometry>

namespace steadiface {
namespace sim {
namespace {

// One vertex of the relief's grid as the camera sees it.
struct Vertex {
  float x = 0, y = 0, z = 0;  // image position [px] and depth [m]
  float u = 0, v = 0;         // texel
  bool valid = false;
};

// The camera's view of the billboard for each band of rows: the billboard's
// local point X appears at K (M X + o).
struct BandPoses {
  std::vector<Eigen::Matrix3d> M;
  std::vector<Eigen::Vector3d> o;
  int band = 1;
};

BandPoses PosesPerBand(const CameraIntrinsics& k,
                       const std::function<double(double)>& row_time,
                       const std::function<Pose(double)>& camera_pose,
                       const Billboard& b, int band) {
  BandPoses bp;
  bp.band = band;
  for (int y0 = 0; y0 < k.height; y0 += band) {
    const int y1 = std::min(k.height, y0 + band);
    const double t = row_time(0.5 * (y0 + y1 - 1));
    const Pose C = camera_pose(t), P = b.pose(t);
    const Eigen::Matrix3d Rcw = C.R.conjugate().toRotationMatrix();
    bp.M.push_back(Rcw * P.R.toRotationMatrix());
    bp.o.push_back(Rcw * (P.p - C.p));
  }
  return bp;
}

// The local point seen at its own row (the rolling shutter's fixed point,
// from the row `y_guess`).
Vertex Project(const CameraIntrinsics& k, const BandPoses& bp,
               const Eigen::Vector3d& local, double y_guess) {
  Vertex v;
  double y = y_guess;
  const int n = static_cast<int>(bp.M.size());
  for (int it = 0; it < 4; ++it) {
    const int i = std::min(n - 1, std::max(0, static_cast<int>(y) / bp.band));
    const Eigen::Vector3d X = bp.M[i] * local + bp.o[i];
    if (X.z() <= 1e-6) return Vertex();
    v.x = static_cast<float>(k.fx * X.x() / X.z() + k.cx);
    v.y = static_cast<float>(k.fy * X.y() / X.z() + k.cy);
    v.z = static_cast<float>(X.z());
    y = std::min(std::max(static_cast<double>(v.y), 0.0), k.height - 1.0);
  }
  v.valid = std::isfinite(v.x) && std::isfinite(v.y);
  return v;
}

cv::Vec4b SampleBgra(const cv::Mat& t, float u, float v) {
  const int x0 = std::min(t.cols - 2, std::max(0, static_cast<int>(u)));
  const int y0 = std::min(t.rows - 2, std::max(0, static_cast<int>(v)));
  const float fx = std::min(1.0f, std::max(0.0f, u - x0)),
              fy = std::min(1.0f, std::max(0.0f, v - y0));
  const cv::Vec4b* r0 = t.ptr<cv::Vec4b>(y0) + x0;
  const cv::Vec4b* r1 = t.ptr<cv::Vec4b>(y0 + 1) + x0;
  cv::Vec4b out;
  for (int c = 0; c < 4; ++c) {
    const float a = (1 - fx) * r0[0][c] + fx * r0[1][c],
                b = (1 - fx) * r1[0][c] + fx * r1[1][c];
    out[c] = static_cast<uchar>((1 - fy) * a + fy * b + 0.5f);
  }
  return out;
}

// Draws one triangle whose corners turn as (0,0), (1,0), (1,1) do in the
// texture (u right, v down): culled when the camera sees its back; each
// pixel centre inside keeps the nearest surface.
void DrawTriangle(const Vertex& a, const Vertex& b, const Vertex& c,
                  const cv::Mat& texture, cv::Mat* layer, cv::Mat* depth) {
  const float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (!(area > 1e-6f)) return;  // seen from behind, or edge-on
  const int x0 =
      std::max(0, static_cast<int>(std::ceil(std::min({a.x, b.x, c.x}))));
  const int x1 = std::min(
      layer->cols - 1, static_cast<int>(std::floor(std::max({a.x, b.x, c.x}))));
  const int y0 =
      std::max(0, static_cast<int>(std::ceil(std::min({a.y, b.y, c.y}))));
  const int y1 = std::min(
      layer->rows - 1, static_cast<int>(std::floor(std::max({a.y, b.y, c.y}))));
  const float inv = 1.0f / area, eps = -1e-4f;
  for (int y = y0; y <= y1; ++y) {
    cv::Vec4b* out = layer->ptr<cv::Vec4b>(y);
    float* zb = depth->ptr<float>(y);
    for (int x = x0; x <= x1; ++x) {
      const float wa = ((b.x - x) * (c.y - y) - (b.y - y) * (c.x - x)) * inv;
      const float wb = ((c.x - x) * (a.y - y) - (c.y - y) * (a.x - x)) * inv;
      const float wc = 1.0f - wa - wb;
      if (wa < eps || wb < eps || wc < eps) continue;
      const float z = wa * a.z + wb * b.z + wc * c.z;
      if (z >= zb[x]) continue;
      const cv::Vec4b px = SampleBgra(texture, wa * a.u + wb * b.u + wc * c.u,
                                      wa * a.v + wb * b.v + wc * c.v);
      if (px[3] == 0) continue;
      out[x] = px;
      zb[x] = z;
    }
  }
}

// The texels of the grid's columns (or rows): every `step`, and the last.
std::vector<int> GridLines(int n, int step) {
  std::vector<int> lines;
  for (int i = 0;; i += step) {
    lines.push_back(std::min(i, n - 1));
    if (i >= n - 1) break;
  }
  return lines;
}

// Whether any texel of the cell is drawn (alpha > 0).
bool CellShows(const cv::Mat& bgra, int u0, int u1, int v0, int v1) {
  for (int v = v0; v <= v1; ++v) {
    const cv::Vec4b* row = bgra.ptr<cv::Vec4b>(v);
    for (int u = u0; u <= u1; ++u) {
      if (row[u][3] > 0) return true;
    }
  }
  return false;
}

}  // namespace

cv::Mat MakeHeadRelief(const cv::Size& size,
                       const Eigen::Vector2d& face_centre_uv,
                       double face_width_px, const HeadReliefOptions& o) {
  cv::Mat depth(size, CV_32F);
  const double cx = 0.5 * (size.width - 1), cy = 0.5 * (size.height - 1);
  const double w = std::max(1.0, face_width_px);
  // The ellipse's half-axes, so that its outline (outline_radius of them)
  // lies across at half the head's breadth when one is given.
  const double ax = o.breadth_face_widths > 0.0
                        ? 0.5 * o.breadth_face_widths * w / o.outline_radius
                        : 0.5 * size.width;
  const double ay = 0.5 * size.height;
  const Eigen::Vector2d nose(face_centre_uv.x(),
                             face_centre_uv.y() + o.nose_below * w);
  for (int y = 0; y < size.height; ++y) {
    float* d = depth.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const double rho = std::min(
          1.0, std::hypot((x - cx) / ax, (y - cy) / ay) / o.outline_radius);
      double z = o.pivot_depth_m * (1.0 - std::sqrt(1.0 - rho * rho));
      const double nx = (x - nose.x()) / (o.nose_sigma_x * w);
      const double ny = (y - nose.y()) / (o.nose_sigma_y * w);
      z -= o.nose_height_m * std::exp(-0.5 * (nx * nx + ny * ny));
      d[x] = static_cast<float>(z);
    }
  }
  return depth;
}

double ReliefDepth(const cv::Mat& depth, const Eigen::Vector2d& uv) {
  const double u = std::min(std::max(uv.x(), 0.0), depth.cols - 1.0);
  const double v = std::min(std::max(uv.y(), 0.0), depth.rows - 1.0);
  const int x0 = std::min(depth.cols - 2, static_cast<int>(u));
  const int y0 = std::min(depth.rows - 2, static_cast<int>(v));
  const double fx = u - x0, fy = v - y0;
  const float* r0 = depth.ptr<float>(y0) + x0;
  const float* r1 = depth.ptr<float>(y0 + 1) + x0;
  return (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) +
         fy * ((1 - fx) * r1[0] + fx * r1[1]);
}

void RenderRelief(const CameraIntrinsics& k,
                  const std::function<double(double)>& row_time,
                  const std::function<Pose(double)>& camera_pose,
                  const Billboard& b, int band, cv::Mat* layer,
                  int grid_texels) {
  *layer = cv::Mat(k.height, k.width, CV_8UC4, cv::Scalar::all(0));
  cv::Mat zbuf(k.height, k.width, CV_32F,
               cv::Scalar(std::numeric_limits<float>::infinity()));
  const BandPoses bp =
      PosesPerBand(k, row_time, camera_pose, b, std::max(1, band));
  const std::vector<int> us = GridLines(b.bgra.cols, std::max(1, grid_texels));
  const std::vector<int> vs = GridLines(b.bgra.rows, std::max(1, grid_texels));
  std::vector<Vertex> grid(us.size() * vs.size());
  double y_guess = k.cy;
  for (size_t j = 0; j < vs.size(); ++j) {
    for (size_t i = 0; i < us.size(); ++i) {
      const Eigen::Vector2d uv(us[i], vs[j]);
      const Eigen::Vector2d xy = (uv - b.anchor_px) * b.metres_per_px;
      Vertex& v = grid[j * us.size() + i];
      v = Project(
          k, bp,
          Eigen::Vector3d(xy.x(), xy.y(), b.depth_m.at<float>(vs[j], us[i])),
          y_guess);
      v.u = static_cast<float>(us[i]);
      v.v = static_cast<float>(vs[j]);
      if (v.valid)
        y_guess =
            std::min(std::max(static_cast<double>(v.y), 0.0), k.height - 1.0);
    }
  }
  for (size_t j = 0; j + 1 < vs.size(); ++j) {
    for (size_t i = 0; i + 1 < us.size(); ++i) {
      const Vertex& v00 = grid[j * us.size() + i];
      const Vertex& v10 = grid[j * us.size() + i + 1];
      const Vertex& v01 = grid[(j + 1) * us.size() + i];
      const Vertex& v11 = grid[(j + 1) * us.size() + i + 1];
      if (!(v00.valid && v10.valid && v01.valid && v11.valid)) continue;
      if (!CellShows(b.bgra, us[i], us[i + 1], vs[j], vs[j + 1])) continue;
      DrawTriangle(v00, v10, v11, b.bgra, layer, &zbuf);
      DrawTriangle(v00, v11, v01, b.bgra, layer, &zbuf);
    }
  }
}

bool IntersectRelief(const Billboard& b, const Pose& P,
                     const Eigen::Vector3d& origin, const Eigen::Vector3d& ray,
                     Eigen::Vector2d* uv) {
  // The ray in the billboard's frame, met first with the plane z = 0, then
  // with the plane at the depth found there, until it settles.
  const Eigen::Vector3d o = P.R.conjugate() * (origin - P.p),
                        d = P.R.conjugate() * ray;
  if (std::abs(d.z()) < 1e-12) return false;
  double z = 0.0;
  Eigen::Vector2d t;
  for (int it = 0; it < 8; ++it) {
    const double s = (z - o.z()) / d.z();
    if (s <= 0.0) return false;
    t = (o + s * d).head<2>() / b.metres_per_px + b.anchor_px;
    if (!(t.x() >= 0.0 && t.y() >= 0.0 && t.x() <= b.bgra.cols - 1.0 &&
          t.y() <= b.bgra.rows - 1.0)) {
      return false;
    }
    if (b.depth_m.empty()) break;
    z = ReliefDepth(b.depth_m, t);
  }
  *uv = t;
  return true;
}

}  // namespace sim
}  // namespace steadiface
