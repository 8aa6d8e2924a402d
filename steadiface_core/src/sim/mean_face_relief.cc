// The simulated head's mean face: ReadPhotoLandmarks and AddMeanFaceDepths
// (sim/head_relief.h).
#include <algorithm>
#include <cmath>
#include <fstream>

#include <Eigen/Cholesky>

#include "steadiface_core/face/landmarks68.h"
#include "steadiface_core/sim/head_relief.h"
#include "steadiface_core/sim/mean_face.h"

namespace steadiface {
namespace sim {
namespace {

// The mean face's width between its jaw ends [m].
double MeanJawWidth() {
  const auto& f = MeanFace68();
  return (f[landmarks68::kJawLeftEnd] - f[landmarks68::kJawRightEnd]).head<2>().norm();
}

// The depth change at each landmark that gives it the mean face's depth
// [m], the eyes' mean on the photo's plane (the mean face's origin).
Eigen::VectorXd LandmarkChanges(const std::vector<Eigen::Vector2d>& uv, double metres_per_unit,
                                const cv::Mat& depth) {
  const auto& face = MeanFace68();
  const int n = static_cast<int>(uv.size());
  Eigen::VectorXd r(n);
  for (int i = 0; i < n; ++i) r[i] = metres_per_unit * face[i].z() - ReliefDepth(depth, uv[i]);
  return r;
}

}  // namespace

bool ReadPhotoLandmarks(const std::string& path, std::vector<Eigen::Vector2d>* out) {
  std::ifstream in(path);
  out->clear();
  double x = 0.0, y = 0.0;
  while (out->size() < landmarks68::kCount && in >> x >> y) out->emplace_back(x, y);
  return out->size() == landmarks68::kCount;
}

bool AddMeanFaceDepths(const std::vector<Eigen::Vector2d>& uv, double metres_per_texel,
                       double sigma_face_widths, cv::Mat* depth) {
  if (uv.size() != MeanFace68().size() || depth == nullptr || depth->empty()) return false;
  for (const Eigen::Vector2d& p : uv) {
    if (!p.allFinite()) return false;
  }
  const double jaw_texels = (uv[landmarks68::kJawLeftEnd] - uv[landmarks68::kJawRightEnd]).norm();
  if (!(jaw_texels > 1.0) || !(metres_per_texel > 0.0) || !(sigma_face_widths > 0.0)) return false;
  // The mean face's depths are in metres for its own jaw width.
  const double scale = jaw_texels * metres_per_texel / MeanJawWidth();
  const Eigen::VectorXd r = LandmarkChanges(uv, scale, *depth);
  const int n = static_cast<int>(uv.size());
  const double sigma = sigma_face_widths * jaw_texels;
  const double k = -0.5 / (sigma * sigma);
  // Weights of the radial basis functions that reproduce r at the
  // landmarks (a small ridge: the lips' inner and outer points lie close).
  Eigen::MatrixXd phi(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) phi(i, j) = std::exp(k * (uv[i] - uv[j]).squaredNorm());
  }
  phi.diagonal().array() += 1e-4;
  const Eigen::VectorXd a = phi.ldlt().solve(r);
  if (!a.allFinite()) return false;
  const int reach = static_cast<int>(std::ceil(4.0 * sigma));
  for (int i = 0; i < n; ++i) {
    const int u0 = std::max(0, static_cast<int>(uv[i].x()) - reach);
    const int u1 = std::min(depth->cols - 1, static_cast<int>(uv[i].x()) + reach);
    const int v0 = std::max(0, static_cast<int>(uv[i].y()) - reach);
    const int v1 = std::min(depth->rows - 1, static_cast<int>(uv[i].y()) + reach);
    for (int v = v0; v <= v1; ++v) {
      float* d = depth->ptr<float>(v);
      for (int u = u0; u <= u1; ++u) {
        const double q = (Eigen::Vector2d(u, v) - uv[i]).squaredNorm();
        d[u] += static_cast<float>(a[i] * std::exp(k * q));
      }
    }
  }
  return true;
}

}  // namespace sim
}  // namespace steadiface
