#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/gyro/row_rotations.h"
#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/warp/warp_geometry.h"

namespace steadiface {

/// Result of checking one pose for undefined output pixels.
struct ProtrusionReport {
  /// True when every output pixel centre maps inside the real frame,
  /// [0, W-1] x [0, H-1] shrunk by the margin asked for.
  bool defined = false;
  /// Largest distance by which a boundary sample falls outside [px]; 0 when
  /// defined.
  double max_outside_px = 0.0;
  /// Real row each boundary sample landed on (for the solver's fixed rows).
  std::vector<double> rows;
};

/// The one implementation of "is every output pixel defined for this pose,
/// and by how much not" (paper §4.2, E_p, and §4.4, protrusion handling).
/// The stabilizer's protrusion cost term, its binary search and the warp all
/// use it.
///
/// It maps samples along the output crop window's boundary (the outer pixel
/// centres, `samples_per_edge` per edge) into the real frame with each
/// sample's own row rotation. The window's image is inside the real frame iff
/// its boundary is (the map is a smooth homeomorphism for any pose the
/// stabilizer produces), which tests check against a brute-force per-pixel
/// check.
class ProtrusionGeometry {
 public:
  ProtrusionGeometry() = default;
  ProtrusionGeometry(const CameraModel& model, const OutputGeometry& output,
                     int samples_per_edge);

  /// The outer pixel centres of `output`'s window, clockwise, corners once,
  /// `samples_per_edge` (at least 2) per edge, in virtual normalized
  /// coordinates: the samples Check() maps (and CropNeed, per crop).
  static std::vector<Eigen::Vector2d> WindowBoundary(const OutputGeometry& output,
                                                     int samples_per_edge);

  /// Boundary samples in virtual normalized coordinates.
  const std::vector<Eigen::Vector2d>& boundary() const { return boundary_; }
  size_t num_samples() const { return boundary_.size(); }

  /// Exact check (rolling-shutter fixed point per sample). `shrink_px`
  /// shrinks the real frame on every side (0 for "defined").
  ProtrusionReport Check(const Eigen::Quaterniond& R_v,
                         const Eigen::Vector2d& t, const RowRotations& rows,
                         double shrink_px) const;

  /// Per-axis amount by which a real pixel lies outside the real frame
  /// shrunk by `shrink_px` (0 inside) [px].
  template <typename T>
  static Eigen::Matrix<T, 2, 1> Outside(const Eigen::Matrix<T, 2, 1>& p,
                                        int width, int height,
                                        double shrink_px) {
    const T lo(shrink_px);
    const T hx(width - 1 - shrink_px), hy(height - 1 - shrink_px);
    Eigen::Matrix<T, 2, 1> o;
    o(0) = p(0) < lo ? lo - p(0) : (p(0) > hx ? p(0) - hx : T(0.0));
    o(1) = p(1) < lo ? lo - p(1) : (p(1) > hy ? p(1) - hy : T(0.0));
    return o;
  }

  /// Residuals for Ceres: 2 per boundary sample, the outside amounts [px]
  /// times `scale`, with each sample's real rotation fixed to `R_r[i]`
  /// (taken from a Check() at the initial pose). A sample behind the camera
  /// gives a large constant penalty.
  template <typename T>
  void Residuals(const Eigen::Quaternion<T>& R_v,
                 const Eigen::Matrix<T, 2, 1>& t,
                 const std::vector<Eigen::Quaterniond>& R_r, double shrink_px,
                 double scale, T* residuals) const {
    const CameraIntrinsics& k = model_.intrinsics();
    for (size_t i = 0; i < boundary_.size(); ++i) {
      Eigen::Matrix<T, 2, 1> p;
      if (!VirtualToRealPixel<T>(model_, R_v, t, R_r[i], boundary_[i], &p)) {
        residuals[2 * i] = T(scale * k.width);
        residuals[2 * i + 1] = T(scale * k.height);
        continue;
      }
      const Eigen::Matrix<T, 2, 1> o =
          Outside<T>(p, k.width, k.height, shrink_px);
      residuals[2 * i] = T(scale) * o(0);
      residuals[2 * i + 1] = T(scale) * o(1);
    }
  }

  const CameraModel& model() const { return model_; }

 private:
  CameraModel model_;
  std::vector<Eigen::Vector2d> boundary_;
};

}  // namespace steadiface
