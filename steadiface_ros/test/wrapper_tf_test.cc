// StabilizerWrapper's transforms: a tree below the camera frame, IMU
// extrinsics taken from TF when it has them, the background layer's frame.
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "wrapper_test_util.h"

namespace steadiface_ros {
namespace wrapper_test {
namespace {

// The TF tree stays a tree: the camera frame keeps the parent its driver or
// URDF gives it (the node never publishes it as a child), every frame the
// node publishes has one parent, and the integrated gyro hangs below the
// camera as <camera_frame>_world, rotated by the state's real rotation.
TEST(WrapperTest, TransformsNeverGiveTheCameraFrameAParent) {
  Sink sink;
  steadiface::PipelineOptions po = Options();
  po.stabilizer.background_layer = true;
  StabilizerWrapper w(po, WrapperOptions(), &sink);
  Feed(&w, TestStream());
  std::map<std::string, std::set<std::string>> parents;
  for (const auto& t : sink.tf)
    parents[t.child_frame_id].insert(t.header.frame_id);
  EXPECT_EQ(parents.count("cam"), 0u);
  for (const auto& [child, p] : parents) EXPECT_EQ(p.size(), 1u) << child;
  ASSERT_EQ(parents["cam_world"], std::set<std::string>{"cam"});
  EXPECT_EQ(parents["cam_stabilized"], std::set<std::string>{"cam"});
  EXPECT_EQ(parents["cam_stabilized_background"], std::set<std::string>{"cam"});
  size_t k = 0;
  for (const auto& t : sink.tf) {
    if (t.child_frame_id != "cam_world") continue;
    ASSERT_LT(k, sink.states.size());
    const auto& a = t.transform.rotation;
    const auto& b = sink.states[k++].real_rotation;
    EXPECT_NEAR(std::abs(a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w), 1.0,
                1e-9);
  }
  EXPECT_EQ(k, sink.states.size());
  // A configured world frame is used as it is.
  Sink named_sink;
  WrapperOptions named;
  named.world_frame = "gyro_world";
  StabilizerWrapper n(Options(), named, &named_sink);
  Feed(&n, TestStream(), 0, 5);
  size_t found = 0;
  for (const auto& t : named_sink.tf) found += t.child_frame_id == "gyro_world";
  EXPECT_EQ(found, 5u);
}

// An IMU in its own frame, rotated 90 deg about the optical axis against
// the camera, whose static TF comes late: until it comes the node warns
// and uses imu/R_cam_imu (identity, wrong here); once TF has it, the
// rotation is taken, the pipeline rebuilt once, and from then on the
// frame-to-frame real rotation is that of an IMU in the camera's frame.
TEST(WrapperTest, LateImuExtrinsicsAreTakenWhenTfHasThem) {
  const Eigen::Quaterniond R_cam_imu(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  Stream rotated = TestStream();
  for (auto& m : rotated.imu) {
    const Eigen::Vector3d w_cam(m.angular_velocity.x, m.angular_velocity.y,
                                m.angular_velocity.z);
    const Eigen::Vector3d w_imu = R_cam_imu.conjugate() * w_cam;
    m.angular_velocity.x = w_imu.x();
    m.angular_velocity.y = w_imu.y();
    m.angular_velocity.z = w_imu.z();
    m.header.frame_id = "imu";
  }
  int asked = 0;
  size_t resolved_at = 0;  // states published when TF had it
  std::string asked_from, asked_to;
  Sink sink, truth_sink;
  auto lookup = [&](const std::string& from, const std::string& to,
                    Eigen::Quaterniond* q) {
    asked_from = from, asked_to = to;
    if (++asked <= 20) return false;  // the static TF is not there yet
    resolved_at = sink.states.size();
    *q = R_cam_imu;
    return true;
  };
  StabilizerWrapper w(Options(), WrapperOptions(), &sink, lookup);
  Feed(&w, rotated, 0, 10);
  EXPECT_EQ(w.CurrentStatus().extrinsics, ExtrinsicsState::kWaitingForTf);
  EXPECT_GT(sink.warnings["extrinsics"], 0);
  Feed(&w, rotated, 10);
  EXPECT_EQ(w.CurrentStatus().extrinsics, ExtrinsicsState::kFromTf);
  EXPECT_EQ(asked, 21);  // asked on every frame until it came, then never again
  EXPECT_EQ(asked_from, "imu");
  EXPECT_EQ(asked_to, "cam");
  EXPECT_EQ(w.CurrentStatus().counters.rebuilds, 1u);
  StabilizerWrapper truth(Options(), WrapperOptions(), &truth_sink);
  Feed(&truth, TestStream());
  ASSERT_EQ(sink.states.size(), truth_sink.states.size());
  auto step = [](const Sink& s, size_t i) {
    auto q = [&](size_t j) {
      const auto& r = s.states[j].real_rotation;
      return Eigen::Quaterniond(r.w, r.x, r.y, r.z);
    };
    return q(i) * q(i - 1).conjugate();
  };
  double before = 0.0, after = 0.0;
  for (size_t i = 1; i < sink.states.size(); ++i) {
    const double e = step(sink, i).angularDistance(step(truth_sink, i));
    if (i >= 2 && i <= 8) before = std::max(before, e);
    if (i > resolved_at) after = std::max(after, e);
  }
  EXPECT_GT(before, 1e-3);  // the identity mounting is visibly wrong
  EXPECT_LT(after, 1e-9);
  EXPECT_GT(resolved_at, 10u);
  EXPECT_LT(resolved_at + 20, sink.states.size());
}

// With stabilizer/background_layer the background layer's virtual camera is
// published beside the subject's: its TF frame, and its pose in `state`,
// equal to a gyro-only run's. Off (the default), neither appears.
TEST(WrapperTest, BackgroundLayerIsPublishedAsItsOwnFrameWhenOn) {
  Sink off_sink, on_sink, gyro_sink;
  StabilizerWrapper off(Options(), WrapperOptions(), &off_sink);
  Feed(&off, TestStream());
  steadiface::PipelineOptions po = Options();
  po.stabilizer.background_layer = true;
  StabilizerWrapper on(po, WrapperOptions(), &on_sink);
  Feed(&on, TestStream());
  steadiface::PipelineOptions go = Options();
  go.stabilizer.gyro_only = true;
  go.landmark_source = steadiface::LandmarkSource::kNone;
  StabilizerWrapper gyro(go, WrapperOptions(), &gyro_sink);
  Feed(&gyro, TestStream());
  auto count = [](const Sink& s, const std::string& child) {
    size_t n = 0;
    for (const auto& t : s.tf) n += t.child_frame_id == child;
    return n;
  };
  EXPECT_EQ(count(off_sink, "cam_stabilized_background"), 0u);
  EXPECT_EQ(count(on_sink, "cam_stabilized_background"),
            TestStream().images.size());
  EXPECT_EQ(count(on_sink, "cam_stabilized"), TestStream().images.size());
  ASSERT_EQ(on_sink.states.size(), gyro_sink.states.size());
  ASSERT_EQ(on_sink.states.size(), off_sink.states.size());
  for (size_t i = 0; i < on_sink.states.size(); ++i) {
    const auto& a = on_sink.states[i];
    EXPECT_FALSE(off_sink.states[i].has_background_layer);
    ASSERT_TRUE(a.has_background_layer);
    EXPECT_EQ(a.background_rotation.x, gyro_sink.states[i].virtual_rotation.x);
    EXPECT_EQ(a.background_rotation.w, gyro_sink.states[i].virtual_rotation.w);
    EXPECT_EQ(a.background_principal_offset[1],
              gyro_sink.states[i].principal_offset[1]);
    // The subject layer is as with one layer.
    EXPECT_EQ(a.virtual_rotation.z, off_sink.states[i].virtual_rotation.z);
  }
  ExpectAllFinite(on_sink);
}

}  // namespace
}  // namespace wrapper_test
}  // namespace steadiface_ros
