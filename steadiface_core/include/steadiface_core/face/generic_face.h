#pragma once

#include <vector>

#include <Eigen/Core>

namespace steadiface {

/// A generic 3D face with the 68 iBUG/dlib landmarks, in metres, in a head
/// frame: x right (the face's left from the viewer's side is -x), y down,
/// z away from the viewer (the nose tip has the most negative z), origin
/// between the eyes at eye depth. Width between the jaw ends ~0.14 m.
/// Procedural and approximate: good for head-pose PnP (runtime) and for the
/// simulators faces,
/// not an anthropometric reference.
const std::vector<Eigen::Vector3d>& GenericFace68();

/// Index ranges of the iBUG 68 layout.
struct Face68 {
  static constexpr int kJaw = 0;         // 0-16
  static constexpr int kRightBrow = 17;  // 17-21 (image left)
  static constexpr int kLeftBrow = 22;   // 22-26
  static constexpr int kNoseBridge = 27; // 27-30, 30 = tip
  static constexpr int kNostrils = 31;   // 31-35
  static constexpr int kRightEye = 36;   // 36-41
  static constexpr int kLeftEye = 42;    // 42-47
  static constexpr int kMouthOuter = 48; // 48-59
  static constexpr int kMouthInner = 60; // 60-67
  static constexpr int kNoseTip = 30;
  static constexpr int kChin = 8;
};

}  // namespace steadiface
