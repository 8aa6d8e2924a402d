#include "steadiface_core/common/so3.h"

#include <gtest/gtest.h>

namespace steadiface {
namespace {

TEST(So3Test, ExpMatchesAngleAxis) {
  for (const Eigen::Vector3d& phi :
       {Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(0, 0, 3.0),
        Eigen::Vector3d(1e-7, 2e-7, -1e-7), Eigen::Vector3d(2.0, 1.0, -0.5)}) {
    const Eigen::Quaterniond q = ExpSO3(phi);
    const Eigen::Quaterniond ref(
        Eigen::AngleAxisd(phi.norm(), phi.normalized()));
    EXPECT_NEAR(AngleBetween(q, ref), 0.0, 1e-12);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
  }
}

TEST(So3Test, LogInvertsExpIncludingSmallAndLargeAngles) {
  for (const Eigen::Vector3d& phi :
       {Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(1e-9, 0, 0),
        Eigen::Vector3d(0, 3.1, 0), Eigen::Vector3d(-1.0, 1.2, 0.7)}) {
    EXPECT_NEAR((LogSO3(ExpSO3(phi)) - phi).norm(), 0.0, 1e-12);
    // Sign invariance.
    const Eigen::Quaterniond neg(-ExpSO3(phi).coeffs());
    EXPECT_NEAR((LogSO3(neg) - phi).norm(), 0.0, 1e-12);
  }
  EXPECT_NEAR(LogSO3(Eigen::Quaterniond::Identity()).norm(), 0.0, 0.0);
}

TEST(So3Test, AlignSignPicksReferenceHemisphere) {
  const Eigen::Quaterniond q = ExpSO3(Eigen::Vector3d(0.1, 0.2, 0.3));
  const Eigen::Quaterniond neg(-q.coeffs());
  EXPECT_GT(AlignSign(neg, q).coeffs().dot(q.coeffs()), 0.0);
  EXPECT_EQ(AlignSign(q, q).coeffs(), q.coeffs());
}

}  // namespace
}  // namespace steadiface
