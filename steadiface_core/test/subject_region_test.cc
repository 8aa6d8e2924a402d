// The layered warp's subject region against closed forms: its outline's
// signed distance (analytic, and on a mesh's grid where the shapes overlap)
// and its blend ramp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "layered_test_util.h"
#include "steadiface_core/layered/subject_region.h"

namespace steadiface {
namespace {

using testing_util::Grid;
using testing_util::Head;
using testing_util::Region;

TEST(SubjectRegionTest, SignedDistanceCoversHeadNeckAndShouldersOnly) {
  const SubjectRegion r = Region();
  EXPECT_LT(r.SignedDistance({320, 150}), -60.0);  // head centre
  EXPECT_LT(r.SignedDistance({320, 240}), 0.0);    // neck
  EXPECT_LT(r.SignedDistance({200, 350}), 0.0);    // shoulder
  EXPECT_GT(r.SignedDistance({100, 100}), 100.0);  // background beside the head
  // Circle-exact: a point 30 px right of the head ellipse's side.
  EXPECT_NEAR(r.SignedDistance({320 + 70 + 30, 150}), 30.0, 1.0);
}

TEST(SubjectRegionTest, BlendStartsAtItsTargetThenRampsAtMostDtOverRamp) {
  SubjectRegionOptions o;
  o.ramp_s = 0.5;
  SubjectRegionTracker t(o);
  CameraModel model;
  ASSERT_TRUE(CameraModel::Create(IntrinsicsFromHorizontalFov(640, 360, 1.1),
                                  CameraModelOptions(), &model)
                  .ok());
  OutputGeometry out;
  ASSERT_TRUE(OutputGeometry::Create(model, OutputOptions(), &out).ok());
  const RowRotations rows(Eigen::Quaterniond::Identity(), 360);
  // A frontal face: 68 points on a 0.2-wide ellipse in normalized units
  // (jaw 0-16 along its lower half, brows 17-26 above the centre).
  FaceObservation face;
  face.valid = true;
  for (int i = 0; i < 68; ++i) {
    const double a = i <= 16 ? M_PI * i / 16.0 : -0.5 * M_PI + 0.05 * (i - 40);
    face.landmarks.emplace_back(0.5 + 0.1 * std::cos(a),
                                0.5 + 0.12 * std::sin(a));
  }
  face.landmark_rows.assign(68, 180.0);
  const Eigen::Quaterniond I = Eigen::Quaterniond::Identity();
  const SubjectRegion& first =
      t.Update(model, out, I, Eigen::Vector2d::Zero(), rows, &face, 1.0, 0.0);
  ASSERT_TRUE(first.valid);
  EXPECT_DOUBLE_EQ(first.blend, 1.0);  // no previous output to jump from
  // The output shows the middle 70 % of the width, magnified 1/0.7: the jaw
  // spans 0.2 of the input width = 0.2 * 640 / 0.7 output px.
  EXPECT_NEAR(first.jaw_width, 0.2 * 640 / 0.7, 3.0);
  EXPECT_NEAR(first.head_centre.x(), 319.5, 2.0);
  // The face is lost: the blend ramps to 0 by at most dt / ramp per frame.
  const double dt = 1.0 / 30;
  double previous = first.blend;
  int frames = 0;
  while (t.region().blend > 0.0 && frames < 100) {
    const SubjectRegion& r = t.Update(model, out, I, Eigen::Vector2d::Zero(),
                                      rows, nullptr, 0.0, dt);
    EXPECT_LE(previous - r.blend, dt / 0.5 + 1e-12);
    EXPECT_DOUBLE_EQ(r.blend_step, previous - r.blend);
    EXPECT_TRUE(r.valid);  // the last region is kept while it fades
    previous = r.blend;
    ++frames;
  }
  EXPECT_NEAR(frames, 15, 1);  // 0.5 s at 30 fps (rounding may add one)
}


// The true depth of an inside point: the distance to the nearest point
// outside the region, searched on a 0.5 px grid, then on a 0.05 px grid
// around the nearest point found (SignedDistance's sign is exact: each
// shape's is, and the union's is their minimum). It overestimates the depth
// by at most half the fine grid's diagonal, 0.036 px [px].
double BruteForceDepth(const SubjectRegion& r, const Eigen::Vector2d& p,
                       Eigen::Vector2d* nearest_point = nullptr) {
  double best = 1e9;
  Eigen::Vector2d nearest = Eigen::Vector2d::Zero();
  auto search = [&](const Eigen::Vector2d& centre, double half, double step) {
    for (double dy = -half; dy <= half; dy += step) {
      for (double dx = -half; dx <= half; dx += step) {
        const Eigen::Vector2d d = centre + Eigen::Vector2d(dx, dy);
        if (d.norm() < best && r.SignedDistance(p + d) > 0.0) {
          best = d.norm();
          nearest = d;
        }
      }
    }
  };
  search(Eigen::Vector2d::Zero(), 150.0, 0.5);
  search(nearest, 0.6, 0.05);
  if (nearest_point != nullptr) *nearest_point = p + nearest;
  return best;
}

// GridDistances equals SignedDistance outside the region and never reads
// shallower than it inside. Where the nearest outline lies within the grid
// (and its one-cell margin), it is within the raster's resolution of the
// true depth, and at most 1 px deeper (0.67 px measured: the rasterized
// outline covers the pixels it touches). An outline beyond that (the shoulders below the frame)
// is not seen: there the depth is to the outline within the grid, which is
// deeper. Under the chin, where the head ellipse and the neck box overlap,
// SignedDistance falls short of the true depth by up to the neck's width;
// GridDistances does not.
TEST(SubjectRegionTest, GridDistancesAreTheTrueDepthInsideAndSignedDistanceOutside) {
  const Grid g;
  double worst_short = 0.0, analytic_short = 0.0, worst_deep = -1e9;
  for (double jaw : {100.0, 150.0, 200.0, 260.0}) {
    const SubjectRegion r = Head(jaw);
    std::vector<double> sd;
    r.GridDistances(g.u, g.v, &sd);
    ASSERT_EQ(sd.size(), static_cast<size_t>(g.n()));
    // The raster: a quarter of the 20 px cell.
    const double res = 0.25 * (g.u[1] - g.u[0]);
    for (int k = 0; k < g.n(); ++k) {
      const double analytic = r.SignedDistance(g.At(k));
      if (analytic > 0.0) {
        EXPECT_EQ(sd[k], analytic) << "vertex " << k;
        continue;
      }
      EXPECT_LE(sd[k], analytic) << "vertex " << k;
      Eigen::Vector2d outline;
      const double truth = BruteForceDepth(r, g.At(k), &outline);
      const double margin = g.u[1] - g.u[0];  // the raster's one cell
      if (outline.x() < g.u.front() - margin || outline.x() > g.u.back() + margin ||
          outline.y() < g.v.front() - margin || outline.y() > g.v.back() + margin) {
        continue;  // an outline beyond the raster is not seen
      }
      EXPECT_GE(sd[k], -truth - 1.0) << "vertex " << k << " reads deeper than it is";
      worst_deep = std::max(worst_deep, -sd[k] - truth);
      EXPECT_LE(sd[k], -truth + 0.02 * truth + std::sqrt(2.0) * res) << "vertex " << k;
      worst_short = std::max(worst_short, truth + sd[k]);
      analytic_short = std::max(analytic_short, truth + analytic);
    }
  }
  std::printf("  inside, short of the true depth by at most %.1f px (SignedDistance: %.1f px), "
              "deeper by at most %.2f px\n",
              worst_short, analytic_short, worst_deep);
  EXPECT_GT(analytic_short, 10.0);  // so the overlap is in the test
}

}  // namespace
}  // namespace steadiface
