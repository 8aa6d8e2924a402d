#include "steadiface_core/face/face_observation.h"

#include <cmath>

namespace steadiface {

void ComputeCentreAndScale(FaceObservation* face) {
  if (face->landmarks.empty()) {
    face->centre.setZero();
    face->scale = 0.0;
    return;
  }
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& p : face->landmarks) c += p;
  c /= static_cast<double>(face->landmarks.size());
  double s2 = 0.0;
  for (const auto& p : face->landmarks) s2 += (p - c).squaredNorm();
  face->centre = c;
  face->scale = std::sqrt(s2 / face->landmarks.size());
}

void ShiftFace(const Eigen::Vector2d& d, FaceObservation* face) {
  for (auto& l : face->landmarks) l += d;
  face->centre += d;
}

}  // namespace steadiface
