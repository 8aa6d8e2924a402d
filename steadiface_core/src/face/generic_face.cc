#include "steadiface_core/face/generic_face.h"

#include <cmath>

namespace steadiface {
namespace {

std::vector<Eigen::Vector3d> Build() {
  std::vector<Eigen::Vector3d> p;  // unit: face width ~1, scaled at the end
  auto depth = [](double x, double y) {
    // A rounded face: edges recede.
    return 0.45 * x * x + 0.15 * y * y;
  };
  // Jaw: 17 points from the right ear (image left) round the chin.
  for (int i = 0; i <= 16; ++i) {
    const double th = M_PI * i / 16.0;
    const double x = -0.5 * std::cos(th);
    const double y = -0.08 + 0.55 * std::sin(th);
    p.emplace_back(x, y, depth(x, y) + 0.05);
  }
  // Brows: arcs above the eyes.
  for (int side = 0; side < 2; ++side) {
    for (int i = 0; i < 5; ++i) {
      const double s = i / 4.0;
      const double x = side == 0 ? -0.38 + 0.3 * s : 0.08 + 0.3 * s;
      const double u = side == 0 ? s : 1.0 - s;
      const double y = -0.27 - 0.06 * std::sin(M_PI * (0.3 + 0.6 * u));
      p.emplace_back(x, y, depth(x, y) - 0.05);
    }
  }
  // Nose bridge to tip.
  for (int i = 0; i < 4; ++i) {
    const double y = -0.17 + 0.075 * i;
    p.emplace_back(0.0, y, -0.06 - 0.05 * i);
  }
  // Nostrils / nose base.
  for (int i = 0; i < 5; ++i) {
    const double x = -0.1 + 0.05 * i;
    p.emplace_back(x, 0.1 - 0.015 * (2 - std::abs(i - 2)) * -1.0, -0.1 + 0.03 * std::abs(i - 2));
  }
  // Eyes: 6 points each, starting at the outer corner.
  for (int side = 0; side < 2; ++side) {
    const double cx = side == 0 ? -0.2 : 0.2;
    const double dir = side == 0 ? 1.0 : -1.0;  // outer -> inner
    const double ang[6] = {M_PI, 2 * M_PI / 3, M_PI / 3, 0.0, -M_PI / 3, -2 * M_PI / 3};
    for (int i = 0; i < 6; ++i) {
      const double x = cx - dir * 0.08 * std::cos(ang[i]);
      const double y = -0.15 - 0.03 * std::sin(ang[i]);
      p.emplace_back(x, y, depth(x, y) - 0.02);
    }
  }
  // Mouth outer: 12 points from the right corner, upper lip first.
  for (int i = 0; i < 12; ++i) {
    const double th = M_PI - 2 * M_PI * i / 12.0;
    const double x = 0.18 * std::cos(th);
    const double y = 0.28 - 0.06 * std::sin(th);
    p.emplace_back(x, y, depth(x, y) - 0.06);
  }
  // Mouth inner: 8 points.
  for (int i = 0; i < 8; ++i) {
    const double th = M_PI - 2 * M_PI * i / 8.0;
    const double x = 0.1 * std::cos(th);
    const double y = 0.28 - 0.02 * std::sin(th);
    p.emplace_back(x, y, depth(x, y) - 0.055);
  }
  for (auto& q : p) q *= 0.14;
  return p;
}

}  // namespace

const std::vector<Eigen::Vector3d>& GenericFace68() {
  static const std::vector<Eigen::Vector3d> model = Build();
  return model;
}

}  // namespace steadiface
