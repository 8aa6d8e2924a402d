#include "steadiface_core/sim/mean_face.h"

#include <cmath>

#include "steadiface_core/face/generic_face.h"
#include "steadiface_core/face/landmarks68.h"

namespace steadiface {
namespace sim {
namespace {

// The generic face's width between its jaw ends [m].
constexpr double kJawWidthM = 0.14;

// The fitted depth of landmark i at x [face widths, +z away from the
// viewer], per group of the 68 (before the eyes' mean is taken off).
double FittedDepth(int i, double x) {
  namespace l68 = landmarks68;
  constexpr int kNostrilMiddle = (l68::kNostrilFirst + l68::kNostrilLast) / 2;
  if (i <= l68::kJawLast) return -0.019 + 0.689 * std::abs(x);
  if (i <= l68::kBrowLast) return -0.091 + 1.229 * x * x;
  if (i <= l68::kNoseTip) return -0.104 - 0.0545 * (i - l68::kNoseBridgeTop);  // root to tip
  if (i <= l68::kNostrilLast) return -0.193 + 0.019 * std::abs(i - kNostrilMiddle);
  if (i <= l68::kLeftEyeLast) return -0.036 * x * x;
  if (i <= l68::kMouthLast) return -0.194 + 3.994 * x * x;  // outer lips
  return -0.189 + 11.6 * x * x;                              // inner lips
}

std::vector<Eigen::Vector3d> Build() {
  namespace l68 = landmarks68;
  std::vector<Eigen::Vector3d> p = GenericFace68();
  for (int i = 0; i < static_cast<int>(p.size()); ++i) {
    p[i].z() = kJawWidthM * FittedDepth(i, p[i].x() / kJawWidthM);
  }
  double eyes = 0.0;
  for (int i = l68::kRightEyeFirst; i <= l68::kLeftEyeLast; ++i) eyes += p[i].z();
  eyes /= l68::kLeftEyeLast - l68::kRightEyeFirst + 1;
  for (auto& q : p) q.z() -= eyes;
  return p;
}

}  // namespace

const std::vector<Eigen::Vector3d>& MeanFace68() {
  static const std::vector<Eigen::Vector3d> model = Build();
  return model;
}

}  // namespace sim
}  // namespace steadiface
