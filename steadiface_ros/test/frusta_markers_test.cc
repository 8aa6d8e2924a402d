// The rviz frusta: closed-form geometry of each camera's image plane, the
// colours that tell the two cameras apart, bounded trails.
#include "steadiface_ros/frusta_markers.h"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

namespace steadiface_ros {
namespace {

steadiface::CameraIntrinsics K(double f, int w = 640, int h = 480) {
  steadiface::CameraIntrinsics k;
  k.width = w;
  k.height = h;
  k.fx = k.fy = f;
  k.cx = w / 2.0;
  k.cy = h / 2.0;
  return k;
}

Eigen::Vector3d V(const geometry_msgs::Point& p) {
  return Eigen::Vector3d(p.x, p.y, p.z);
}

const visualization_msgs::Marker* Find(const visualization_msgs::MarkerArray& a,
                                       int type, int nth) {
  for (const auto& m : a.markers) {
    if (m.type == type && nth-- == 0) return &m;
  }
  return nullptr;
}

TEST(FrustaMarkersTest, EachFrustumIsItsCamerasImagePlaneAtTheGivenDepth) {
  FrustaMarkers f(30, 1.0);
  std_msgs::Header h;
  h.frame_id = "steadiface_world";
  EXPECT_TRUE(f.Make(h, K(500), K(700)).markers.empty());  // nothing added yet
  const Eigen::Quaterniond real = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond virt(
      Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()));
  f.Add(real, virt);
  const visualization_msgs::MarkerArray a = f.Make(h, K(500), K(700));
  ASSERT_FALSE(a.markers.empty());
  for (const auto& m : a.markers)
    EXPECT_EQ(m.header.frame_id, "steadiface_world");
  const auto* real_lines = Find(a, visualization_msgs::Marker::LINE_LIST, 0);
  const auto* virt_lines = Find(a, visualization_msgs::Marker::LINE_LIST, 1);
  ASSERT_TRUE(real_lines && virt_lines);
  ASSERT_EQ(real_lines->points.size(), 16u);
  // Apex at the origin; the first corner is pixel (0, 0) at 1 m.
  EXPECT_LT(V(real_lines->points[0]).norm(), 1e-12);
  EXPECT_LT((V(real_lines->points[1]) -
             Eigen::Vector3d(-320.0 / 500, -240.0 / 500, 1))
                .norm(),
            1e-12);
  // The virtual plane: its own (narrower) field of view, turned by 0.05 rad.
  const Eigen::Vector3d want =
      virt * Eigen::Vector3d(-320.0 / 700, -240.0 / 700, 1);
  EXPECT_LT((V(virt_lines->points[1]) - want).norm(), 1e-12);
  // Distinct colours: orange (real) and green (virtual).
  EXPECT_GT(real_lines->color.r, 0.9);
  EXPECT_LT(real_lines->color.g, 0.6);
  EXPECT_GT(virt_lines->color.g, 0.8);
  EXPECT_LT(virt_lines->color.r, 0.3);
  // Unique ids within the namespace.
  std::set<int> ids;
  for (const auto& m : a.markers) ids.insert(m.id);
  EXPECT_EQ(ids.size(), a.markers.size());
  // Labels.
  EXPECT_EQ(Find(a, visualization_msgs::Marker::TEXT_VIEW_FACING, 0)->text,
            "real camera");
  EXPECT_EQ(Find(a, visualization_msgs::Marker::TEXT_VIEW_FACING, 1)->text,
            "virtual camera");
}

TEST(FrustaMarkersTest, TrailsFollowTheOpticalAxisAndStayBounded) {
  FrustaMarkers f(30, 1.0);
  for (int i = 0; i < 50; ++i) {
    const double a = 0.02 * std::sin(1.7 * i);  // a shaking real camera
    f.Add(Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX())),
          Eigen::Quaterniond::Identity());
  }
  EXPECT_EQ(f.trail_size(), 30u);
  f.Add(Eigen::Quaterniond(NAN, 0, 0, 0),
        Eigen::Quaterniond::Identity());  // skipped
  EXPECT_EQ(f.trail_size(), 30u);
  std_msgs::Header h;
  const visualization_msgs::MarkerArray a = f.Make(h, K(500), K(500));
  const auto* real_trail = Find(a, visualization_msgs::Marker::LINE_STRIP, 0);
  const auto* virt_trail = Find(a, visualization_msgs::Marker::LINE_STRIP, 1);
  ASSERT_TRUE(real_trail && virt_trail);
  ASSERT_EQ(real_trail->points.size(), 30u);
  // The newest real point: the optical axis turned by the last angle.
  const double last = 0.02 * std::sin(1.7 * 49);
  EXPECT_LT((V(real_trail->points.back()) -
             Eigen::AngleAxisd(last, Eigen::Vector3d::UnitX()) *
                 Eigen::Vector3d::UnitZ())
                .norm(),
            1e-12);
  double real_len = 0, virt_len = 0;
  for (size_t i = 1; i < 30; ++i) {
    real_len +=
        (V(real_trail->points[i]) - V(real_trail->points[i - 1])).norm();
    virt_len +=
        (V(virt_trail->points[i]) - V(virt_trail->points[i - 1])).norm();
  }
  EXPECT_GT(real_len, 0.5);  // jagged: ~30 steps of up to 0.04 m
  EXPECT_LT(virt_len, 1e-12);
  f.Clear();
  EXPECT_TRUE(f.Make(h, K(500), K(500)).markers.empty());
}

}  // namespace
}  // namespace steadiface_ros
