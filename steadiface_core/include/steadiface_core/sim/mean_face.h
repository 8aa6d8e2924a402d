#pragma once

#include <vector>

#include <Eigen/Core>

namespace steadiface {
namespace sim {

/// A mean human face's 68 iBUG/dlib landmarks in 3D, for the simulated
/// head (HeadReliefOptions::mean_face): the generic face's layout
/// (face/generic_face.h) with depths least-squares fitted to a published
/// mean 3D face of the 68 landmarks (the in-the-wild mean shape that
/// OpenFace's head pose uses, 14.5 cm between the jaw ends): RMS 2.5 mm, at
/// most 5.3 mm off over the 68 points. Metres, x right, y down, z away from
/// the viewer, origin between the eyes at their mean depth, 0.14 m between
/// the jaw ends. The jaw's ends lie 4.6 cm behind the eyes and the nose tip
/// 3.7 cm in front of them: about twice as deep as the generic face that
/// the runtime's PnP uses.
const std::vector<Eigen::Vector3d>& MeanFace68();

}  // namespace sim
}  // namespace steadiface
