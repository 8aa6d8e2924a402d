#pragma once

#include <array>

#include <Eigen/Core>

namespace steadiface {
namespace visual {

/// One tracked feature's bearings over its last few frames, each carried
/// into the present camera by the turns fitted since (the rolling-shutter
/// turn between the rows the feature was seen on). A point of the distant
/// scene stays where its carried bearings say; a near object that moves
/// with the frame's rotation to within the inlier threshold each frame
/// (its parallax under the hand's translation, or its own motion) strays
/// from them frame by frame.
class SceneTrail {
 public:
  static constexpr int kMaxFrames = 16;

  /// Starts again from nothing (the feature's track is new, or a frame's
  /// rotation was not known).
  void Clear() { count_ = 0; }

  /// The camera turned by `turn` (a rotation vector in the camera: the
  /// scene's bearing b moves to Exp(-turn) b) between the feature's last
  /// sighting, at `before` (x, y, 1), and this one, at `now` (x, y). Keeps
  /// at most `frames` past bearings and returns the largest distance from
  /// `now` of where any of them lands [normalized image units].
  double Advance(const Eigen::Vector3d& turn, const Eigen::Vector3d& before,
                 const Eigen::Vector2d& now, int frames);

  int count() const { return count_; }

 private:
  int count_ = 0;
  std::array<Eigen::Vector3d, kMaxFrames> carried_;  // oldest first
};

}  // namespace visual
}  // namespace steadiface
