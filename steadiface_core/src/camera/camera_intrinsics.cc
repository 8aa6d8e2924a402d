#include "steadiface_core/camera/camera_intrinsics.h"

#include <cmath>
#include <sstream>

namespace steadiface {

bool CameraIntrinsics::HasDistortion() const {
  if (distortion == DistortionModel::kNone) return false;
  for (double k : distortion_coeffs) {
    if (k != 0.0) return true;
  }
  return false;
}

CameraIntrinsics IntrinsicsFromHorizontalFov(int width, int height,
                                             double hfov_rad) {
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = 0.5 * width / std::tan(0.5 * hfov_rad);
  k.fy = k.fx;
  k.cx = 0.5 * (width - 1);
  k.cy = 0.5 * (height - 1);
  return k;
}

Status ValidateIntrinsics(const CameraIntrinsics& k) {
  std::ostringstream err;
  if (k.width <= 0 || k.height <= 0) {
    err << "image size must be positive, got " << k.width << "x" << k.height;
  } else if (!std::isfinite(k.fx) || !std::isfinite(k.fy) || k.fx <= 0.0 ||
             k.fy <= 0.0) {
    err << "focal lengths fx, fy must be finite and > 0 px, got fx=" << k.fx
        << " fy=" << k.fy;
  } else if (!std::isfinite(k.cx) || !std::isfinite(k.cy)) {
    err << "principal point cx, cy must be finite, got cx=" << k.cx
        << " cy=" << k.cy;
  } else {
    for (double c : k.distortion_coeffs) {
      if (!std::isfinite(c)) {
        err << "distortion coefficients must be finite";
        break;
      }
    }
    const size_t n = k.distortion_coeffs.size();
    if (err.tellp() == 0 && k.distortion == DistortionModel::kPlumbBob &&
        n != 0 && n != 4 && n != 5 && n != 8) {
      err << "plumb_bob/rational_polynomial needs 4, 5 or 8 coefficients, got "
          << n;
    }
    if (err.tellp() == 0 && k.distortion == DistortionModel::kEquidistant &&
        n != 0 && n != 4) {
      err << "equidistant needs 4 coefficients, got " << n;
    }
  }
  if (err.tellp() != 0) return Status::Error("camera intrinsics: " + err.str());
  return Status::Ok();
}

}  // namespace steadiface
