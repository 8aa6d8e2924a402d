#include "steadiface_core/camera/camera_model.h"

#include <gtest/gtest.h>

#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace {

CameraModel MakeModel(const CameraIntrinsics& k, double zoom = 1.0) {
  CameraModel m;
  CameraModelOptions o;
  o.virtual_focal_scale = zoom;
  const Status s = CameraModel::Create(k, o, &m);
  EXPECT_TRUE(s.ok()) << s.message();
  return m;
}

CameraIntrinsics Skewed() {
  CameraIntrinsics k;
  k.width = 1280;
  k.height = 720;
  k.fx = 1000.0;
  k.fy = 1010.0;  // non-square pixels
  k.cx = 655.5;   // off-centre principal point
  k.cy = 350.25;
  return k;
}

TEST(CameraModelTest, PixelNormalizedRoundTrip) {
  const CameraModel m = MakeModel(Skewed());
  for (double x : {0.0, 17.3, 640.0, 1279.0}) {
    for (double y : {0.0, 359.5, 719.0}) {
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector2d back = m.NormalizedToPixel(m.PixelToNormalized(p));
      EXPECT_NEAR(back.x(), x, 1e-9);
      EXPECT_NEAR(back.y(), y, 1e-9);
    }
  }
  // The calibrated principal point is the paper's (0.5, 0.5).
  const Eigen::Vector2d c = m.PixelToNormalized({655.5, 350.25});
  EXPECT_NEAR(c.x(), 0.5, 1e-12);
  EXPECT_NEAR(c.y(), 0.5, 1e-12);
  EXPECT_NEAR(m.real_focal(), 1000.0 / 1280.0, 1e-12);
}

TEST(CameraModelTest, NormalizedCoordinatesArePinholeWithRealK) {
  // A 3D point seen through (fx, fy, cx, cy) must land, after
  // PixelToNormalized, exactly where K_r puts its ray.
  const CameraModel m = MakeModel(Skewed());
  const CameraIntrinsics& k = m.intrinsics();
  const Eigen::Vector3d X(0.31, -0.17, 1.9);
  const Eigen::Vector2d pixel(k.fx * X.x() / X.z() + k.cx,
                              k.fy * X.y() / X.z() + k.cy);
  const Eigen::Vector3d h = m.RealK() * X;
  const Eigen::Vector2d expected = h.hnormalized();
  const Eigen::Vector2d n = m.PixelToNormalized(pixel);
  EXPECT_NEAR(n.x(), expected.x(), 1e-12);
  EXPECT_NEAR(n.y(), expected.y(), 1e-12);
}

TEST(CameraModelTest, HomographyIsIdentityForEqualRotationsAndZeroOffset) {
  const CameraModel m = MakeModel(Skewed());
  const Eigen::Quaterniond R = ExpSO3(Eigen::Vector3d(0.1, -0.2, 0.05));
  const Eigen::Matrix3d H = m.Homography(R, Eigen::Vector2d::Zero(), R);
  const Eigen::Matrix3d Hn = H / H(2, 2);
  EXPECT_TRUE(Hn.isApprox(Eigen::Matrix3d::Identity(), 1e-12)) << Hn;
}

TEST(CameraModelTest, HomographyZoomsAboutCentreWithVirtualFocal) {
  const double zoom = 1.25;
  const CameraModel m = MakeModel(Skewed(), zoom);
  const Eigen::Quaterniond R = ExpSO3(Eigen::Vector3d(-0.3, 0.02, 0.4));
  for (const Eigen::Vector2d& L :
       {Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0.5, 0.5),
        Eigen::Vector2d(0.93, 0.71)}) {
    Eigen::Vector2d V;
    ASSERT_TRUE(m.Project(L, R, Eigen::Vector2d::Zero(), R, &V));
    const Eigen::Vector2d expected =
        Eigen::Vector2d(0.5, 0.5) + zoom * (L - Eigen::Vector2d(0.5, 0.5));
    EXPECT_NEAR(V.x(), expected.x(), 1e-12);
    EXPECT_NEAR(V.y(), expected.y(), 1e-12);
  }
}

TEST(CameraModelTest, PureRotationMovesPointAtInfinityAsKRKinv) {
  const CameraModel m = MakeModel(Skewed());
  const Eigen::Matrix3d K = m.RealK();
  // Two real camera poses (world -> camera).
  const Eigen::Quaterniond R1 = ExpSO3(Eigen::Vector3d(0.02, 0.1, -0.03));
  const Eigen::Quaterniond R2 = ExpSO3(Eigen::Vector3d(-0.05, 0.04, 0.12));
  // Points at infinity: world directions.
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d(0.1, -0.2, 1.0), Eigen::Vector3d(-0.3, 0.25, 1.0),
        Eigen::Vector3d(0.0, 0.0, 1.0)}) {
    const Eigen::Vector2d p1 = (K * (R1 * d)).hnormalized();
    const Eigen::Vector2d p2 = (K * (R2 * d)).hnormalized();
    // The virtual camera at R2 sees real frame-1 pixel p1 at p2.
    Eigen::Vector2d v;
    ASSERT_TRUE(m.Project(p1, R2, Eigen::Vector2d::Zero(), R1, &v));
    EXPECT_NEAR(v.x(), p2.x(), 1e-12);
    EXPECT_NEAR(v.y(), p2.y(), 1e-12);
    // And Π equals K R K^-1 with R = R2 R1^-1.
    const Eigen::Matrix3d KRKinv =
        K * (R2 * R1.conjugate()).toRotationMatrix() * K.inverse();
    const Eigen::Matrix3d H =
        m.Homography(R2, Eigen::Vector2d::Zero(), R1);
    EXPECT_TRUE((H / H(2, 2)).isApprox(KRKinv / KRKinv(2, 2), 1e-12));
    const Eigen::Vector2d vh = (H * p1.homogeneous()).hnormalized();
    EXPECT_NEAR(vh.x(), p2.x(), 1e-12);
    EXPECT_NEAR(vh.y(), p2.y(), 1e-12);
  }
}

TEST(CameraModelTest, PrincipalOffsetShiftsProjection) {
  const CameraModel m = MakeModel(Skewed());
  const Eigen::Quaterniond Rr = ExpSO3(Eigen::Vector3d(0.01, 0.02, 0.03));
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.03, -0.02, 0.0));
  const Eigen::Vector2d L(0.4, 0.6), t(0.013, -0.021);
  Eigen::Vector2d v0, v1;
  ASSERT_TRUE(m.Project(L, Rv, Eigen::Vector2d::Zero(), Rr, &v0));
  ASSERT_TRUE(m.Project(L, Rv, t, Rr, &v1));
  EXPECT_NEAR((v1 - v0 - t).norm(), 0.0, 1e-12);
  // VirtualK carries 0.5 + t as principal point.
  EXPECT_DOUBLE_EQ(m.VirtualK(t)(0, 2), 0.5 + t.x());
  EXPECT_DOUBLE_EQ(m.VirtualK(t)(1, 2), 0.5 + t.y());
}

TEST(CameraModelTest, UnprojectInvertsProject) {
  const CameraModel m = MakeModel(Skewed(), 1.1);
  const Eigen::Quaterniond Rr = ExpSO3(Eigen::Vector3d(0.2, -0.1, 0.3));
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.15, -0.05, 0.25));
  const Eigen::Vector2d t(-0.02, 0.01);
  for (double x = 0.0; x <= 1.0; x += 0.25) {
    for (double y = 0.2; y <= 0.8; y += 0.2) {
      const Eigen::Vector2d L(x, y);
      Eigen::Vector2d V, back;
      ASSERT_TRUE(m.Project(L, Rv, t, Rr, &V));
      ASSERT_TRUE(m.Unproject(V, Rv, t, Rr, &back));
      EXPECT_NEAR((back - L).norm(), 0.0, 1e-12);
      // Project agrees with the homography matrix.
      const Eigen::Vector2d vh =
          (m.Homography(Rv, t, Rr) * L.homogeneous()).hnormalized();
      EXPECT_NEAR((vh - V).norm(), 0.0, 1e-12);
    }
  }
}

TEST(CameraModelTest, PointBehindVirtualCameraIsReported) {
  const CameraModel m = MakeModel(Skewed());
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.0, M_PI, 0.0));
  Eigen::Vector2d v(-7, -7);
  EXPECT_FALSE(m.Project({0.5, 0.5}, Rv, Eigen::Vector2d::Zero(),
                         Eigen::Quaterniond::Identity(), &v));
  EXPECT_EQ(v, Eigen::Vector2d(-7, -7));
}

TEST(CameraModelTest, IntrinsicsFromFov) {
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 360, M_PI / 2);
  EXPECT_NEAR(k.fx, 320.0, 1e-9);
  EXPECT_NEAR(k.cx, 319.5, 1e-12);
  EXPECT_NEAR(k.cy, 179.5, 1e-12);
  EXPECT_FALSE(k.HasDistortion());
}

TEST(CameraModelTest, InvalidIntrinsicsAndOptionsAreRejected) {
  CameraModel m;
  CameraIntrinsics k = Skewed();
  k.width = 0;
  Status s = CameraModel::Create(k, CameraModelOptions(), &m);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("size"), std::string::npos) << s.message();
  k = Skewed();
  k.fy = -1.0;
  EXPECT_FALSE(CameraModel::Create(k, CameraModelOptions(), &m).ok());
  k = Skewed();
  k.cx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(CameraModel::Create(k, CameraModelOptions(), &m).ok());
  k = Skewed();
  k.distortion = DistortionModel::kEquidistant;
  k.distortion_coeffs = {0.1, 0.2};
  s = CameraModel::Create(k, CameraModelOptions(), &m);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("equidistant"), std::string::npos);
  CameraModelOptions o;
  o.virtual_focal_scale = 0.0;
  s = CameraModel::Create(Skewed(), o, &m);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("virtual_focal_scale"), std::string::npos);
}

}  // namespace
}  // namespace steadiface
