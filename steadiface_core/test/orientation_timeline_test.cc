#include "steadiface_core/gyro/orientation_timeline.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Time At(double seconds) { return Time(FromSeconds(seconds)); }

// An analytic, non-commuting camera motion: q_wc(t) = Rz(a(t)) * Rx(b(t)),
// a = A sin(2 pi f1 t), b = B sin(2 pi f2 t). Body rate:
// omega = Rx(b)^T (0, 0, a') + (b', 0, 0).
struct Wobble {
  double A = 0.2, f1 = 5.0, B = 0.1, f2 = 7.0;
  Eigen::Quaterniond Q(double t) const {
    return Eigen::Quaterniond(Eigen::AngleAxisd(
               A * std::sin(2 * M_PI * f1 * t), Eigen::Vector3d::UnitZ())) *
           Eigen::Quaterniond(Eigen::AngleAxisd(
               B * std::sin(2 * M_PI * f2 * t), Eigen::Vector3d::UnitX()));
  }
  Eigen::Vector3d Omega(double t) const {
    const double b = B * std::sin(2 * M_PI * f2 * t);
    const double da = A * 2 * M_PI * f1 * std::cos(2 * M_PI * f1 * t);
    const double db = B * 2 * M_PI * f2 * std::cos(2 * M_PI * f2 * t);
    const Eigen::Matrix3d Rx =
        Eigen::AngleAxisd(b, Eigen::Vector3d::UnitX()).toRotationMatrix();
    return Rx.transpose() * Eigen::Vector3d(0, 0, da) +
           Eigen::Vector3d(db, 0, 0);
  }
};

TEST(OrientationTimelineTest, ConstantRateIntegratesExactly) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  const Eigen::Vector3d w(0.3, -0.5, 0.8);
  for (int i = 0; i <= 400; ++i) {
    ASSERT_EQ(tl.AddSample({At(i / 200.0), w}), SampleResult::kAccepted);
  }
  for (double t : {0.0, 0.5, 1.0, 1.337, 2.0}) {
    Eigen::Quaterniond q;
    ASSERT_EQ(tl.CameraToWorld(At(t), &q), QueryResult::kOk);
    EXPECT_NEAR(AngleBetween(q, ExpSO3(w * t)), 0.0, 1e-12) << "t=" << t;
    // R_r is the conjugate.
    Eigen::Quaterniond R_r;
    ASSERT_EQ(tl.RealRotation(At(t), &R_r), QueryResult::kOk);
    EXPECT_NEAR(AngleBetween(R_r, q.conjugate()), 0.0, 1e-15);
  }
}

// Max angle error of the timeline against Wobble over 2 s, checked at
// samples and halfway between them.
double WobbleError(double rate_hz) {
  const Wobble m;
  OrientationTimeline tl{OrientationTimelineOptions()};
  const int n = static_cast<int>(2.0 * rate_hz);
  for (int i = 0; i <= n; ++i) {
    const double t = i / rate_hz;
    EXPECT_EQ(tl.AddSample({At(t), m.Omega(t)}), SampleResult::kAccepted);
  }
  double worst = 0.0;
  for (int i = 0; i < 2 * n; ++i) {
    const double t = i / (2.0 * rate_hz);
    Eigen::Quaterniond q;
    EXPECT_EQ(tl.CameraToWorld(At(t), &q), QueryResult::kOk);
    worst = std::max(worst, AngleBetween(q, m.Q(t)));
  }
  return worst;
}

// A configured gyro bias is removed in the IMU frame, before the rotation
// into the camera frame: a reading of w + b with bias b integrates as w.
TEST(OrientationTimelineTest, GyroBiasIsSubtractedInTheImuFrame) {
  OrientationTimelineOptions o;
  o.R_cam_imu = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  o.gyro_bias = Eigen::Vector3d(0.01, -0.02, 0.005);
  OrientationTimeline tl(o);
  const Eigen::Vector3d w_imu(0.3, -0.5, 0.8);
  for (int i = 0; i <= 400; ++i) {
    ASSERT_EQ(tl.AddSample({At(i / 200.0), w_imu + o.gyro_bias}), SampleResult::kAccepted);
  }
  Eigen::Quaterniond q;
  ASSERT_EQ(tl.CameraToWorld(At(1.5), &q), QueryResult::kOk);
  EXPECT_NEAR(AngleBetween(q, ExpSO3(o.R_cam_imu * w_imu * 1.5)), 0.0, 1e-12);
  o.gyro_bias = Eigen::Vector3d(2.0, 0, 0);
  EXPECT_FALSE(ValidateOrientationTimelineOptions(o).ok());
}

TEST(OrientationTimelineTest, SinusoidalRateStaysWithinStatedErrorAt200Hz) {
  // Motion of +-11 deg at 5 Hz and +-6 deg at 7 Hz (peak rate ~7 rad/s,
  // far harsher than hand shake). Stated bound at 200 Hz: 1e-3 rad
  // (0.06 deg), dominated by slerp between samples, not by integration.
  const double err200 = WobbleError(200.0);
  EXPECT_LT(err200, 1e-3) << err200;
  // Higher sample rates converge (second order or better).
  const double err800 = WobbleError(800.0);
  EXPECT_LT(err800, err200 / 8.0) << err200 << " vs " << err800;
}

// Max angle error at the sample instants (no slerp involved) after 2 s.
double WobbleDriftAtSamples(double rate_hz) {
  const Wobble m;
  OrientationTimeline tl{OrientationTimelineOptions()};
  double worst = 0.0;
  const int n = static_cast<int>(2.0 * rate_hz);
  for (int i = 0; i <= n; ++i) {
    const double t = i / rate_hz;
    tl.AddSample({At(t), m.Omega(t)});
    Eigen::Quaterniond q;
    EXPECT_EQ(tl.CameraToWorld(At(t), &q), QueryResult::kOk);
    worst = std::max(worst, AngleBetween(q, m.Q(t)));
  }
  return worst;
}

TEST(OrientationTimelineTest, IntegrationAtSamplesIsThirdOrder) {
  // At the sample instants only the integration error remains: stated bound
  // 2e-4 rad (0.011 deg) after 2 s of the harsh wobble at 200 Hz, and third
  // order convergence (doubling the rate cuts it by ~8).
  const double e200 = WobbleDriftAtSamples(200.0);
  const double e400 = WobbleDriftAtSamples(400.0);
  EXPECT_LT(e200, 2e-4) << e200;
  EXPECT_LT(e400, e200 / 6.0) << e200 << " vs " << e400;
}

TEST(OrientationTimelineTest, SlerpBetweenSamples) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  // Two samples 0.1 s apart with a constant rate: slerp is exact.
  const Eigen::Vector3d w(0.0, 2.0, 0.0);
  tl.AddSample({At(10.0), w});
  tl.AddSample({At(10.1), w});
  for (double s : {0.0, 0.25, 0.5, 0.9, 1.0}) {
    Eigen::Quaterniond q;
    ASSERT_EQ(tl.CameraToWorld(At(10.0 + 0.1 * s), &q), QueryResult::kOk);
    EXPECT_NEAR(AngleBetween(q, ExpSO3(w * 0.1 * s)), 0.0, 1e-12);
  }
  Eigen::Vector3d omega;
  ASSERT_EQ(tl.AngularVelocity(At(10.05), &omega), QueryResult::kOk);
  EXPECT_NEAR((omega - w).norm(), 0.0, 1e-12);
}

TEST(OrientationTimelineTest, QueriesOutsideTheSpan) {
  OrientationTimelineOptions o;
  o.max_extrapolation_s = 0.02;
  OrientationTimeline tl(o);
  Eigen::Quaterniond q;
  EXPECT_EQ(tl.CameraToWorld(At(1.0), &q), QueryResult::kEmpty);
  const Eigen::Vector3d w(1.0, 0.0, 0.0);
  tl.AddSample({At(1.0), w});
  tl.AddSample({At(1.005), w});
  EXPECT_EQ(tl.CameraToWorld(At(0.999), &q), QueryResult::kBeforeStart);
  EXPECT_EQ(tl.CameraToWorld(At(1.005 + 0.03), &q), QueryResult::kAfterEnd);
  ASSERT_EQ(tl.CameraToWorld(At(1.015), &q), QueryResult::kExtrapolated);
  EXPECT_NEAR(AngleBetween(q, ExpSO3(w * 0.015)), 0.0, 1e-12);
  EXPECT_TRUE(tl.Covers(At(1.002)));
  EXPECT_FALSE(tl.Covers(At(1.006)));
}

TEST(OrientationTimelineTest, ExtrinsicRotationIsApplied) {
  // The IMU is mounted rotated: omega_imu = R_cam_imu^-1 omega_cam.
  OrientationTimelineOptions o;
  o.R_cam_imu = ExpSO3(Eigen::Vector3d(0.0, 0.0, M_PI / 2)) *
                ExpSO3(Eigen::Vector3d(M_PI / 2, 0.0, 0.0));
  OrientationTimeline tl(o);
  const Wobble m;
  for (int i = 0; i <= 200; ++i) {
    const double t = i / 200.0;
    tl.AddSample({At(t), o.R_cam_imu.conjugate() * m.Omega(t)});
  }
  Eigen::Quaterniond q;
  ASSERT_EQ(tl.CameraToWorld(At(0.8), &q), QueryResult::kOk);
  EXPECT_LT(AngleBetween(q, m.Q(0.8)), 2e-4);
  Eigen::Vector3d omega;
  ASSERT_EQ(tl.AngularVelocity(At(0.8), &omega), QueryResult::kOk);
  EXPECT_NEAR((omega - m.Omega(0.8)).norm(), 0.0, 1e-9);
}

TEST(OrientationTimelineTest, TimeOffsetIsApplied) {
  // IMU clock lags the camera clock by 7.5 ms: t_cam = t_imu + 0.0075.
  OrientationTimelineOptions o;
  o.imu_time_offset_s = 0.0075;
  OrientationTimeline tl(o);
  const Wobble m;
  for (int i = 0; i <= 400; ++i) {
    const double t_cam = i / 200.0;
    tl.AddSample({At(t_cam - 0.0075), m.Omega(t_cam)});
  }
  EXPECT_EQ(tl.oldest(), At(0.0));
  EXPECT_EQ(tl.newest(), At(2.0));
  Eigen::Quaterniond q;
  for (double t : {0.3, 1.005, 1.7}) {
    ASSERT_EQ(tl.CameraToWorld(At(t), &q), QueryResult::kOk);
    EXPECT_LT(AngleBetween(q, m.Q(t)), 1e-3);
  }
}


TEST(OrientationTimelineTest, OffsetCorrectionActsAsALargerOffset) {
  // Configured offset 0 while the camera clock leads by 20 ms: a correction
  // of +20 ms makes every query read what a timeline configured with the
  // right offset reads (coverage, orientation, rate, mean speed).
  OrientationTimelineOptions wrong, right;
  right.imu_time_offset_s = 0.020;
  OrientationTimeline a(wrong), b(right);
  const Wobble m;
  for (int i = 0; i <= 400; ++i) {
    const GyroSample s{At(i / 200.0), m.Omega(i / 200.0 + 0.020)};
    a.AddSample(s);
    b.AddSample(s);
  }
  a.set_offset_correction(0.020);
  EXPECT_DOUBLE_EQ(a.offset_correction(), 0.020);
  EXPECT_EQ(a.oldest(), b.oldest());
  EXPECT_EQ(a.newest(), b.newest());
  EXPECT_FALSE(a.Covers(At(0.01)));
  EXPECT_TRUE(a.Covers(At(2.02)));
  Eigen::Quaterniond qa, qb;
  Eigen::Vector3d wa, wb;
  for (double t : {0.3, 1.0051, 2.01}) {
    ASSERT_EQ(a.CameraToWorld(At(t), &qa), QueryResult::kOk);
    ASSERT_EQ(b.CameraToWorld(At(t), &qb), QueryResult::kOk);
    EXPECT_LT(AngleBetween(qa, qb), 1e-12);
    // World frame: the camera at the first sample (t_cam = 20 ms).
    EXPECT_LT(AngleBetween(qa, m.Q(0.020).conjugate() * m.Q(t)), 1e-3);
    ASSERT_EQ(a.AngularVelocity(At(t), &wa), QueryResult::kOk);
    ASSERT_EQ(b.AngularVelocity(At(t), &wb), QueryResult::kOk);
    EXPECT_LT((wa - wb).norm(), 1e-12);
  }
  double ma = 0.0, mb = 0.0;
  ASSERT_TRUE(a.MeanAngularSpeed(At(0.5), At(0.9), &ma));
  ASSERT_TRUE(b.MeanAngularSpeed(At(0.5), At(0.9), &mb));
  EXPECT_DOUBLE_EQ(ma, mb);
}
TEST(OrientationTimelineTest, BadSamplesAreRejectedAndCounted) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  const Eigen::Vector3d w(0.1, 0.2, 0.3);
  ASSERT_EQ(tl.AddSample({At(1.0), w}), SampleResult::kAccepted);
  ASSERT_EQ(tl.AddSample({At(1.01), w}), SampleResult::kAccepted);
  EXPECT_EQ(tl.AddSample({At(1.02), {kNaN, 0, 0}}), SampleResult::kNonFinite);
  EXPECT_EQ(tl.AddSample({At(1.02), {0, kInf, 0}}), SampleResult::kNonFinite);
  EXPECT_EQ(tl.AddSample({At(1.02), {0, 0, 100.0}}),
            SampleResult::kImplausibleRate);
  EXPECT_EQ(tl.AddSample({At(1.01), w}), SampleResult::kDuplicateStamp);
  EXPECT_EQ(tl.AddSample({At(1.005), w}), SampleResult::kOutOfOrder);
  EXPECT_EQ(tl.AddSample({At(0.5), w}), SampleResult::kOutOfOrder);
  const TimelineStats& s = tl.stats();
  EXPECT_EQ(s.count(SampleResult::kAccepted), 2u);
  EXPECT_EQ(s.count(SampleResult::kNonFinite), 2u);
  EXPECT_EQ(s.count(SampleResult::kImplausibleRate), 1u);
  EXPECT_EQ(s.count(SampleResult::kDuplicateStamp), 1u);
  EXPECT_EQ(s.count(SampleResult::kOutOfOrder), 2u);
  EXPECT_EQ(s.rejected(), 6u);
  // The timeline is untouched by rejections.
  EXPECT_EQ(tl.size(), 2u);
  Eigen::Quaterniond q;
  ASSERT_EQ(tl.CameraToWorld(At(1.01), &q), QueryResult::kOk);
  EXPECT_NEAR(AngleBetween(q, ExpSO3(w * 0.01)), 0.0, 1e-12);
  EXPECT_STREQ(SampleResultName(SampleResult::kOutOfOrder), "out_of_order");
}

TEST(OrientationTimelineTest, GapsAreCounted) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  tl.AddSample({At(0.0), Eigen::Vector3d::Zero()});
  tl.AddSample({At(0.005), Eigen::Vector3d::Zero()});
  tl.AddSample({At(0.5), Eigen::Vector3d::Zero()});
  EXPECT_EQ(tl.stats().gaps, 1u);
}

TEST(OrientationTimelineTest, BufferStaysBoundedAfterAMillionSamples) {
  OrientationTimelineOptions o;
  o.buffer_duration_s = 5.0;
  o.max_samples = 4000;
  OrientationTimeline tl(o);
  const Wobble m;
  size_t max_size = 0;
  for (int i = 0; i < 1000000; ++i) {
    const double t = i / 1000.0;  // 1 kHz for 1000 s
    ASSERT_EQ(tl.AddSample({At(t), m.Omega(t)}), SampleResult::kAccepted);
    max_size = std::max(max_size, tl.size());
  }
  EXPECT_LE(max_size, 4000u);
  EXPECT_LE(ToSeconds(tl.newest() - tl.oldest()), 5.0);
  EXPECT_EQ(tl.stats().trimmed, 1000000u - tl.size());
  // Still correct at the end: relative rotation over the last second matches
  // the analytic one (the world frame is the first sample's, long gone).
  Eigen::Quaterniond q0, q1;
  ASSERT_EQ(tl.CameraToWorld(At(998.5), &q0), QueryResult::kOk);
  ASSERT_EQ(tl.CameraToWorld(At(999.0), &q1), QueryResult::kOk);
  const Eigen::Quaterniond rel = q0.conjugate() * q1;
  const Eigen::Quaterniond rel_true = m.Q(998.5).conjugate() * m.Q(999.0);
  EXPECT_LT(AngleBetween(rel, rel_true), 1e-4);
}

TEST(OrientationTimelineTest, SampleCountCapAlsoBounds) {
  OrientationTimelineOptions o;
  o.buffer_duration_s = 600.0;
  o.max_samples = 100;
  OrientationTimeline tl(o);
  for (int i = 0; i < 1000; ++i) {
    tl.AddSample({At(i * 0.01), Eigen::Vector3d::Zero()});
  }
  EXPECT_EQ(tl.size(), 100u);
}

TEST(OrientationTimelineTest, MeanAngularSpeedOverWindow) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  // |omega| = 1 rad/s for t < 1 s, 3 rad/s after.
  for (int i = 0; i <= 400; ++i) {
    const double t = i / 200.0;
    const double s = t < 1.0 ? 1.0 : 3.0;
    tl.AddSample({At(t), Eigen::Vector3d(0.6 * s, 0.0, 0.8 * s)});
  }
  double mean = 0.0;
  ASSERT_TRUE(tl.MeanAngularSpeed(At(0.1), At(0.9), &mean));
  EXPECT_NEAR(mean, 1.0, 1e-12);
  ASSERT_TRUE(tl.MeanAngularSpeed(At(1.2), At(1.9), &mean));
  EXPECT_NEAR(mean, 3.0, 1e-12);
  ASSERT_TRUE(tl.MeanAngularSpeed(At(0.5), At(1.5), &mean));
  EXPECT_NEAR(mean, 2.0, 0.02);
  EXPECT_FALSE(tl.MeanAngularSpeed(At(5.0), At(6.0), &mean));
  EXPECT_FALSE(tl.MeanAngularSpeed(At(1.0), At(1.0), &mean));
}

TEST(OrientationTimelineTest, ResetStartsANewEpoch) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  tl.AddSample({At(100.0), Eigen::Vector3d(1, 0, 0)});
  tl.AddSample({At(100.1), Eigen::Vector3d(1, 0, 0)});
  tl.Reset();
  EXPECT_TRUE(tl.empty());
  // Earlier stamps are accepted after the reset (time jumped back).
  EXPECT_EQ(tl.AddSample({At(1.0), Eigen::Vector3d::Zero()}),
            SampleResult::kAccepted);
  Eigen::Quaterniond q;
  ASSERT_EQ(tl.CameraToWorld(At(1.0), &q), QueryResult::kOk);
  EXPECT_NEAR(AngleBetween(q, Eigen::Quaterniond::Identity()), 0.0, 1e-15);
  EXPECT_EQ(tl.stats().resets, 1u);
}

// Orientations given outright (the visual rotation source): queries
// interpolate between them, with the offset correction as for gyro samples,
// and a gyro sample after them integrates on from the last one.
TEST(OrientationTimelineTest, OrientationsGivenOutrightAreInterpolatedAndContinued) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  const Eigen::Quaterniond a = ExpSO3(Eigen::Vector3d(0.0, 0.1, 0.0));
  const Eigen::Quaterniond b = ExpSO3(Eigen::Vector3d(0.0, 0.2, 0.0));
  const Eigen::Vector3d w(0.0, 1.0, 0.0);  // 0.1 rad in 0.1 s
  ASSERT_EQ(tl.AddOrientation(Time(FromSeconds(1.0)), a, w), SampleResult::kAccepted);
  ASSERT_EQ(tl.AddOrientation(Time(FromSeconds(1.1)), b, w), SampleResult::kAccepted);
  EXPECT_EQ(tl.AddOrientation(Time(FromSeconds(1.05)), b, w), SampleResult::kOutOfOrder);
  EXPECT_EQ(tl.AddOrientation(Time(FromSeconds(1.2)), b, Eigen::Vector3d(kNaN, 0, 0)),
            SampleResult::kNonFinite);
  Eigen::Quaterniond q;
  ASSERT_TRUE(QuerySucceeded(tl.CameraToWorld(Time(FromSeconds(1.05)), &q)));
  EXPECT_NEAR(AngleBetween(q, ExpSO3(Eigen::Vector3d(0.0, 0.15, 0.0))), 0.0, 1e-9);
  // A gyro sample 0.1 s later at the same rate: 0.1 rad further.
  GyroSample g;
  g.stamp = Time(FromSeconds(1.2));
  g.angular_velocity = w;
  ASSERT_EQ(tl.AddSample(g), SampleResult::kAccepted);
  ASSERT_TRUE(QuerySucceeded(tl.CameraToWorld(Time(FromSeconds(1.2)), &q)));
  EXPECT_NEAR(AngleBetween(q, ExpSO3(Eigen::Vector3d(0.0, 0.3, 0.0))), 0.0, 1e-9);
  // With an offset correction, a node given at camera time t is found there.
  OrientationTimeline c{OrientationTimelineOptions()};
  c.set_offset_correction(0.01);
  ASSERT_EQ(c.AddOrientation(Time(FromSeconds(2.0)), a, w), SampleResult::kAccepted);
  ASSERT_EQ(c.AddOrientation(Time(FromSeconds(2.1)), b, w), SampleResult::kAccepted);
  EXPECT_EQ(c.newest(), Time(FromSeconds(2.1)));
  ASSERT_TRUE(QuerySucceeded(c.CameraToWorld(Time(FromSeconds(2.0)), &q)));
  EXPECT_NEAR(AngleBetween(q, a), 0.0, 1e-9);
}

TEST(OrientationTimelineTest, OptionsValidation) {
  OrientationTimelineOptions o;
  EXPECT_TRUE(ValidateOrientationTimelineOptions(o).ok());
  o.buffer_duration_s = 0.0;
  Status s = ValidateOrientationTimelineOptions(o);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("imu.buffer_duration"), std::string::npos);
  o = OrientationTimelineOptions();
  o.R_cam_imu.coeffs() << 0, 0, 0, 2;
  EXPECT_FALSE(ValidateOrientationTimelineOptions(o).ok());
  o = OrientationTimelineOptions();
  o.imu_time_offset_s = kNaN;
  EXPECT_FALSE(ValidateOrientationTimelineOptions(o).ok());
}

}  // namespace
}  // namespace steadiface
