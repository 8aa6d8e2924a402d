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

}  // namespace steadiface
