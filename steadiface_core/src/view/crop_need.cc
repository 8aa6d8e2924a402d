#include "steadiface_core/view/crop_need.h"

#include "steadiface_core/warp/protrusion.h"
#include "steadiface_core/warp/warp_geometry.h"

namespace steadiface {

double CropNeed(const CameraModel& model, const OutputGeometry& output,
                const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                const RowRotations& rows, int samples_per_edge, int steps) {
  // The window's samples at r (ProtrusionGeometry's), each mapped into the
  // real frame through its own row; without building a ProtrusionGeometry
  // (which copies the camera model).
  const CameraIntrinsics& k = model.intrinsics();
  auto defined_at = [&](double r) {
    double row = 0.5 * (k.height - 1);
    for (const Eigen::Vector2d& V : ProtrusionGeometry::WindowBoundary(
             output.WithCropRatio(r), samples_per_edge)) {
      Eigen::Vector2d p;
      if (!VirtualToRealPixelRS(model, R_v, t, rows, V, 6, 1e-3, &p, &row) ||
          ProtrusionGeometry::Outside<double>(p, k.width, k.height, 0.0)
                  .squaredNorm() > 0.0) {
        return false;
      }
    }
    return true;
  };
  // Most needs are below 0.2: bisect [0, 0.25], else [0.25, 0.4].
  double lo = 0.0, hi = 0.25;  // hi: defined
  if (!defined_at(hi)) {
    lo = hi;
    hi = 0.4;
    if (!defined_at(hi)) return hi;
  } else if (defined_at(lo)) {
    return lo;
  }
  for (int i = 0; i < steps; ++i) {
    const double mid = 0.5 * (lo + hi);
    (defined_at(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace steadiface
