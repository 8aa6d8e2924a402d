// StabilizerWrapper with no ROS master on a clean stream: frames, states,
// infos and landmarks out, the pipelined mode, latency, reconfigure and a
// time jump back.
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

TEST(WrapperTest, CleanStreamIsStabilizedFrameByFrame) {
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  Feed(&w, TestStream());
  EXPECT_EQ(sink.states.size(), TestStream().images.size());
  EXPECT_EQ(sink.images.size(), TestStream().images.size());
  EXPECT_EQ(w.CurrentStatus().counters.extrapolated, 0u);
  ExpectAllFinite(sink);
  std::vector<ros::Time> stamps;
  for (const auto& t : sink.tf) {
    if (t.child_frame_id == "cam_stabilized") stamps.push_back(t.header.stamp);
  }
  ASSERT_EQ(stamps.size(), TestStream().images.size());
  for (size_t i = 1; i < stamps.size(); ++i)
    EXPECT_GT(stamps[i], stamps[i - 1]);
}

// A missing landmark model (a one-time install, not a rosdep key) leaves the
// wrapper running gyro-only: every frame out, the same poses as with face
// processing off, and the reason reported once and kept in the status.
TEST(WrapperTest, MissingLandmarkModelFallsBackToGyroOnly) {
  Sink off_sink, missing_sink;
  StabilizerWrapper off(Options(), WrapperOptions(), &off_sink);
  Feed(&off, TestStream());
  steadiface::PipelineOptions o = Options();
  o.landmark_source = steadiface::LandmarkSource::kDlib;
  o.face.landmark_model_path =
      "/nonexistent/shape_predictor_68_face_landmarks.dat";
  StabilizerWrapper missing(o, WrapperOptions(), &missing_sink);
  EXPECT_EQ(missing.pipeline_options().landmark_source,
            steadiface::LandmarkSource::kNone);
  Feed(&missing, TestStream());
  EXPECT_EQ(missing_sink.errors["landmark_model"], 1);
  EXPECT_EQ(missing_sink.errors.count("pipeline"), 0u);
  const std::string why = missing.CurrentStatus().landmark_model_error;
  EXPECT_NE(why.find("/nonexistent/shape_predictor_68_face_landmarks.dat"),
            std::string::npos);
  EXPECT_NE(why.find("apt-get install libdlib-data"), std::string::npos) << why;
  EXPECT_TRUE(off.CurrentStatus().landmark_model_error.empty());
  ASSERT_EQ(missing_sink.states.size(), TestStream().images.size());
  ASSERT_EQ(off_sink.states.size(), missing_sink.states.size());
  for (size_t i = 0; i < off_sink.states.size(); ++i) {
    const auto& a = off_sink.states[i].virtual_rotation;
    const auto& b = missing_sink.states[i].virtual_rotation;
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.y, b.y);
    EXPECT_EQ(a.z, b.z);
    EXPECT_EQ(a.w, b.w);
  }
  ExpectAllFinite(missing_sink);
}

// A sink that does not consume the stabilized pixels (the bag tool with
// only a report) gets each frame's output camera_info through
// PublishOutputInfo, and no image; everything else is what a sink that
// takes the images gets.
TEST(WrapperTest, SinkWithoutImagesGetsTheSameInfosAndStates) {
  struct InfoOnlySink : public Sink {
    bool WantsImage() const override { return false; }
    void PublishOutputInfo(const sensor_msgs::CameraInfoPtr& c) override {
      infos.push_back(c);
    }
  };
  for (bool pipelined : {false, true}) {
    Sink a;
    InfoOnlySink b;
    WrapperOptions wo;
    wo.pipelined = pipelined;
    StabilizerWrapper wa(Options(), wo, &a), wb(Options(), wo, &b);
    Feed(&wa, TestStream());
    Feed(&wb, TestStream());
    ASSERT_EQ(a.images.size(), TestStream().images.size());
    EXPECT_TRUE(b.images.empty());
    ASSERT_EQ(b.infos.size(), a.infos.size());
    ASSERT_EQ(b.states.size(), a.states.size());
    for (size_t i = 0; i < a.infos.size(); ++i) {
      EXPECT_EQ(b.infos[i]->header.stamp, a.infos[i]->header.stamp);
      EXPECT_EQ(b.infos[i]->header.frame_id, a.infos[i]->header.frame_id);
      EXPECT_EQ(b.infos[i]->width, a.infos[i]->width);
      EXPECT_EQ(b.infos[i]->height, a.infos[i]->height);
      EXPECT_TRUE(b.infos[i]->K == a.infos[i]->K) << "frame " << i;
      EXPECT_EQ(b.states[i].virtual_rotation.w, a.states[i].virtual_rotation.w);
      EXPECT_EQ(b.states[i].principal_offset[0],
                a.states[i].principal_offset[0]);
    }
    ASSERT_EQ(b.tf.size(), a.tf.size());
  }
}

// pipelined (frame n renders on a second thread while frame n+1 is
// processed): the same images, states and TF, in the same order, as the
// one-stage wrapper; each frame is published by the next one or by the
// hold / flush, never lost; in layered mode too.
TEST(WrapperTest, PipelinedPublishesTheSameFramesInOrder) {
  for (steadiface::WarpMode mode :
       {steadiface::WarpMode::kGlobal, steadiface::WarpMode::kLayered,
        steadiface::WarpMode::kComposite}) {
    steadiface::PipelineOptions po = Options();
    po.warp.mode = mode;
    Sink a, b;
    WrapperOptions one, two;
    two.pipelined = true;
    StabilizerWrapper wa(po, one, &a), wb(po, two, &b);
    Feed(&wa, TestStream());
    // Frames wait for their successor (33 ms at 30 fps, within the 0.1 s
    // hold).
    Feed(&wb, TestStream());
    ASSERT_EQ(b.images.size(), a.images.size());
    ASSERT_EQ(b.states.size(), a.states.size());
    ASSERT_EQ(a.images.size(), TestStream().images.size());
    for (size_t i = 0; i < a.images.size(); ++i) {
      EXPECT_EQ(b.images[i]->header.stamp, a.images[i]->header.stamp);
      EXPECT_TRUE(b.images[i]->data == a.images[i]->data) << "frame " << i;
      EXPECT_EQ(b.states[i].header.stamp, a.states[i].header.stamp);
      EXPECT_EQ(b.states[i].virtual_rotation.w, a.states[i].virtual_rotation.w);
    }
    ASSERT_EQ(b.tf.size(), a.tf.size());
    EXPECT_EQ(wb.CurrentStatus().counters.frames_out, wa.CurrentStatus().counters.frames_out);
  }
  // A frame with no successor is published once the hold runs out.
  Sink c;
  WrapperOptions held;
  held.pipelined = true;
  StabilizerWrapper wc(Options(), held, &c);
  const Stream& s = TestStream();
  size_t g = 0;
  const ros::Time last_row =
      s.images[0]->header.stamp + ros::Duration(s.readout + 0.006);
  while (g < s.imu.size() && s.imu[g].header.stamp <= last_row)
    wc.OnImu(s.imu[g++]);
  wc.OnImage(s.images[0], s.info, s.images[0]->header.stamp);
  EXPECT_EQ(c.images.size(), 0u);  // rendering, held for its successor
  wc.OnTimer(s.images[0]->header.stamp + ros::Duration(0.11));
  EXPECT_EQ(c.images.size(), 1u);
}

// Latency parts in `state` on the sink's clock: image arrival, waiting for
// the gyro to cover the last row, publication (the test's clock does not
// advance during processing). Offline (no clock) they stay 0.
TEST(WrapperTest, StateReportsLatencyAndItsParts) {
  struct ClockSink : public Sink {
    ros::Time now;
    ros::Time Now() const override { return now; }
  } sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  const Stream& s = TestStream();
  size_t g = 0;
  for (int i = 0; i < 10; ++i) {
    const ros::Time stamp = s.images[i]->header.stamp;
    // Gyro up to the first row only: the frame must wait.
    while (g < s.imu.size() && s.imu[g].header.stamp <= stamp)
      w.OnImu(s.imu[g++]);
    sink.now = stamp + ros::Duration(0.020);
    w.OnImage(s.images[i], s.info, sink.now);
    EXPECT_EQ(sink.states.size(), static_cast<size_t>(i))
        << "processed before the gyro covered it";
    sink.now = stamp + ros::Duration(0.030);
    const ros::Time last_row = stamp + ros::Duration(s.readout + 0.006);
    while (g < s.imu.size() && s.imu[g].header.stamp <= last_row)
      w.OnImu(s.imu[g++]);
    ASSERT_EQ(sink.states.size(), static_cast<size_t>(i + 1));
    const steadiface::StabilizerState& st = sink.states.back();
    EXPECT_NEAR(st.arrival_latency_ms, 20.0, 1e-3);
    EXPECT_NEAR(st.gyro_wait_ms, 10.0, 1e-3);
    EXPECT_NEAR(st.latency_ms, 30.0, 1e-3);
  }
  Sink offline;
  StabilizerWrapper w2(Options(), WrapperOptions(), &offline);
  Feed(&w2, s, 0, 5);
  ASSERT_FALSE(offline.states.empty());
  for (const auto& st : offline.states) {
    EXPECT_EQ(st.latency_ms, 0.0);
    EXPECT_EQ(st.arrival_latency_ms, 0.0);
    EXPECT_EQ(st.gyro_wait_ms, 0.0);
  }
}

TEST(WrapperTest, TimeJumpBackResetsAndTheSecondPassMatchesTheFirst) {
  // A `rosbag play --loop` restart: the same stream twice.
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  const Stream& st = TestStream();
  Feed(&w, st);
  const size_t n = sink.states.size();
  Feed(&w, st);
  ASSERT_EQ(sink.states.size(), 2 * n);
  EXPECT_EQ(w.CurrentStatus().counters.time_jumps, 1u);
  for (size_t i = 0; i < n; ++i) {
    const auto& a = sink.states[i];
    const auto& b = sink.states[n + i];
    EXPECT_EQ(a.header.stamp, b.header.stamp);
    EXPECT_NEAR(a.virtual_rotation.x, b.virtual_rotation.x, 1e-12);
    EXPECT_NEAR(a.virtual_rotation.w, b.virtual_rotation.w, 1e-12);
    EXPECT_NEAR(a.principal_offset[0], b.principal_offset[0], 1e-12);
  }
  // TF strictly increasing within each epoch.
  std::vector<ros::Time> stamps;
  for (const auto& t : sink.tf) {
    if (t.child_frame_id == "cam_stabilized") stamps.push_back(t.header.stamp);
  }
  int decreases = 0;
  for (size_t i = 1; i < stamps.size(); ++i) {
    if (stamps[i] <= stamps[i - 1]) ++decreases;
  }
  EXPECT_EQ(decreases, 1);  // exactly at the epoch change
}

TEST(WrapperTest, ReconfigureRequestsApplyOnTheNextFrame) {
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  const Stream& st = TestStream();
  Feed(&w, st, 0, 10);
  steadiface::StabilizerOptions o = w.pipeline_options().stabilizer;
  o.weights.distortion = 7.5;
  w.RequestStabilizerOptions(o);
  Feed(&w, st, 10, 12);
  EXPECT_EQ(sink.states[9].w_distortion, 200.0);
  EXPECT_EQ(sink.states[10].w_distortion, 7.5);
}

}  // namespace
}  // namespace wrapper_test
}  // namespace steadiface_ros
