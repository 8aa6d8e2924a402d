#pragma once

#include <Eigen/Core>

#include "steadiface_core/warp/warper.h"

namespace steadiface {
namespace testing_util {

// A mesh of `cells` x `cells` cells over a w x h output whose vertices
// sample the input at A (u, v) + b: an affine warp made by hand, so tests
// of the warp kernels reach flips, zoom-out, steep rotations and every edge.
// Header-only: the AArch64 check (test/aarch64/) builds without gtest.
inline WarpMesh AffineMesh(int w, int h, int cells, const Eigen::Matrix2f& A,
                           const Eigen::Vector2f& b) {
  WarpMesh m;
  m.cols = m.rows = cells + 1;
  for (int i = 0; i <= cells; ++i) {
    m.u.push_back(-0.5 + (w * static_cast<double>(i)) / cells);
    m.v.push_back(-0.5 + (h * static_cast<double>(i)) / cells);
  }
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) {
      const Eigen::Vector2f uv(static_cast<float>(m.u[i]),
                               static_cast<float>(m.v[j]));
      m.source.push_back(A * uv + b);
      m.source_row.push_back(m.source.back().y());
    }
  }
  return m;
}

}  // namespace testing_util
}  // namespace steadiface
