#include "steadiface_core/visual/scene_trail.h"

#include <algorithm>
#include <limits>

#include <Eigen/Geometry>

#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace visual {

double SceneTrail::Advance(const Eigen::Vector3d& turn,
                           const Eigen::Vector3d& before,
                           const Eigen::Vector2d& now, int frames) {
  frames = std::min(std::max(frames, 1), kMaxFrames);
  if (count_ == 0) carried_[count_++] = before;
  const Eigen::Matrix3d R = ExpSO3(-turn).toRotationMatrix();
  double worst = 0.0;
  for (int j = 0; j < count_; ++j) {
    carried_[j] = R * carried_[j];
    if (carried_[j].z() <= 0.0) return std::numeric_limits<double>::infinity();
    worst =
        std::max(worst, (carried_[j].head<2>() / carried_[j].z() - now).norm());
  }
  // This sighting joins; the oldest beyond `frames` leaves.
  const Eigen::Vector3d seen(now.x(), now.y(), 1.0);
  if (count_ < frames) {
    carried_[count_++] = seen;
  } else {
    std::rotate(carried_.begin(), carried_.begin() + 1,
                carried_.begin() + count_);
    carried_[count_ - 1] = seen;
  }
  return worst;
}

}  // namespace visual
}  // namespace steadiface
