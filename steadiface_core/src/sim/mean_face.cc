#include "steadiface_core/sim/mean_face.h"

#include <cmath>

#include "steadiface_core/face/generic_face.h"

namespace steadiface {
namespace sim {
namespace {

// The generic face's width between its jaw ends [m].
constexpr double kJawWidthM = 0.14;

// The fitted depth of landmark i at x [face widths, +z away from the
// viewer], per group of the 68 (before the eyes' mean is taken off).
double FittedDepth(int i, double x) {
  if (i <= 16) return -0.019 + 0.689 * std::abs(x);  // jaw
  if (i <= 26) return -0.091 + 1.229 * x * x;        // brows
  if (i <= 30) return -0.104 - 0.0545 * (i - 27);    // nose bridge, root to tip
  if (i <= 35) return -0.193 + 0.019 * std::abs(i - 33);  // nostrils
  if (i <= 47) return -0.036 * x * x;                      // eyes
  if (i <= 59) return -0.194 + 3.994 * x * x;              // outer lips
  return -0.189 + 11.6 * x * x;                            // inner lips
}

std::vector<Eigen::Vector3d> Build() {
  std::vector<Eigen::Vector3d> p = GenericFace68();
  double eyes = 0.0;
  for (int i = 0; i < static_cast<int>(p.size()); ++i) {
    p[i].z() = kJawWidthM * FittedDepth(i, p[i].x() / kJawWidthM);
    if (i >= 36 && i <= 47) eyes += p[i].z() / 12.0;
  }
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
