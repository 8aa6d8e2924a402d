// StabilizerWrapper under bad input, faults and time jumps, with no ROS
// master: simulated frames and IMU as messages, a recording sink.
#include "steadiface_ros/stabilizer_wrapper.h"

#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <set>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

#include "steadiface_core/sim/simulator.h"
#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Sink : public OutputSink {
  std::vector<sensor_msgs::ImagePtr> images;
  std::vector<sensor_msgs::CameraInfoPtr> infos;
  std::vector<steadiface::StabilizerState> states;
  std::vector<steadiface::FaceLandmarks> landmarks;
  std::vector<geometry_msgs::TransformStamped> tf;
  std::map<std::string, int> warnings, errors;
  void PublishImage(const sensor_msgs::ImagePtr& i,
                    const sensor_msgs::CameraInfoPtr& c) override {
    images.push_back(i);
    infos.push_back(c);
  }
  void PublishLandmarks(const steadiface::FaceLandmarks& m) override {
    landmarks.push_back(m);
  }
  void PublishState(const steadiface::StabilizerState& m) override {
    states.push_back(m);
  }
  void PublishTf(
      const std::vector<geometry_msgs::TransformStamped>& t) override {
    tf.insert(tf.end(), t.begin(), t.end());
  }
  bool WantsDebugImage() const override { return false; }
  void PublishDebugImage(const sensor_msgs::ImagePtr&) override {}
  void Warn(const std::string& k, const std::string&) override {
    ++warnings[k];
  }
  void Error(const std::string& k, const std::string&) override { ++errors[k]; }
};

// A short simulated stream as messages.
struct Stream {
  std::vector<sensor_msgs::Imu> imu;
  std::vector<sensor_msgs::ImagePtr> images;
  sensor_msgs::CameraInfoPtr info;
  double readout = 0.0;
};

const Stream& TestStream() {
  static const Stream s = [] {
    Stream st;
    steadiface::sim::SimulatorOptions o;
    o.data_dir = STEADIFACE_TEST_DATA_DIR;
    EXPECT_TRUE(steadiface::sim::ApplyPreset("walk", &o).ok());
    o.width = 320;
    o.height = 180;
    o.duration_s = 2.0;
    std::unique_ptr<steadiface::sim::Simulator> sim;
    EXPECT_TRUE(steadiface::sim::Simulator::Create(o, &sim).ok());
    st.readout = o.readout_s;
    const ros::Duration shift(1000.0);
    for (size_t i = 0; i < sim->imu().size(); ++i) {
      const steadiface::GyroSample& g = sim->imu()[i];
      sensor_msgs::Imu m;
      m.header.stamp = ToRosTime(g.stamp) + shift;
      m.header.frame_id = "cam";
      m.angular_velocity.x = g.angular_velocity.x();
      m.angular_velocity.y = g.angular_velocity.y();
      m.angular_velocity.z = g.angular_velocity.z();
      const Eigen::Vector3d& a = sim->accel()[i].linear_acceleration;
      m.linear_acceleration.x = a.x();
      m.linear_acceleration.y = a.y();
      m.linear_acceleration.z = a.z();
      st.imu.push_back(m);
    }
    const steadiface::CameraIntrinsics& k = sim->intrinsics();
    st.info.reset(new sensor_msgs::CameraInfo);
    st.info->width = k.width;
    st.info->height = k.height;
    st.info->K = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
    st.info->header.frame_id = "cam";
    for (int i = 0; i < sim->num_frames(); ++i) {
      cv::Mat f;
      steadiface::sim::SimTruth t;
      EXPECT_TRUE(sim->Render(i, &f, &t).ok()) << i;
      std_msgs::Header h;
      h.stamp = ToRosTime(t.stamp) + shift;
      h.frame_id = "cam";
      st.images.push_back(cv_bridge::CvImage(h, "bgr8", f).toImageMsg());
    }
    return st;
  }();
  return s;
}

steadiface::PipelineOptions Options() {
  steadiface::PipelineOptions o;
  o.shutter.readout_time_s = TestStream().readout;
  o.landmark_source =
      steadiface::LandmarkSource::kNone;  // fast; faces are tested elsewhere
  return o;
}

// Feeds the stream in time order (IMU up to each frame's last row first).
void Feed(StabilizerWrapper* w, const Stream& s, int from = 0, int to = -1,
          const std::function<void(sensor_msgs::Imu*)>& imu_fault = {},
          const std::function<sensor_msgs::ImagePtr(int)>& image_fault = {}) {
  if (to < 0) to = static_cast<int>(s.images.size());
  size_t g = 0;
  const ros::Time first = s.images[from]->header.stamp;
  while (g < s.imu.size() && s.imu[g].header.stamp < first - ros::Duration(0.2))
    ++g;
  for (int i = from; i < to; ++i) {
    const ros::Time last_row =
        s.images[i]->header.stamp + ros::Duration(s.readout + 0.006);
    while (g < s.imu.size() && s.imu[g].header.stamp <= last_row) {
      sensor_msgs::Imu m = s.imu[g++];
      if (imu_fault) imu_fault(&m);
      w->OnImu(m);
    }
    sensor_msgs::ImagePtr img = image_fault ? image_fault(i) : s.images[i];
    if (!img) continue;
    w->OnImage(img, s.info, img->header.stamp);
    w->OnTimer(img->header.stamp);
  }
  w->Flush();
}

void ExpectAllFinite(const Sink& sink) {
  for (const auto& s : sink.states) {
    for (double v :
         {s.virtual_rotation.x, s.virtual_rotation.y, s.virtual_rotation.z,
          s.virtual_rotation.w, s.principal_offset[0], s.principal_offset[1],
          s.energy_fit, s.w_fit, s.total_ms}) {
      ASSERT_TRUE(std::isfinite(v));
    }
  }
  for (const auto& t : sink.tf) {
    const auto& q = t.transform.rotation;
    ASSERT_TRUE(std::isfinite(q.x) && std::isfinite(q.y) &&
                std::isfinite(q.z) && std::isfinite(q.w));
  }
  for (const auto& c : sink.infos) {
    for (double v : c->K) ASSERT_TRUE(std::isfinite(v));
  }
}

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

// A sink that also keeps the debug images.
struct DebugSink : public Sink {
  std::vector<sensor_msgs::ImagePtr> debug;
  bool WantsDebugImage() const override { return true; }
  void PublishDebugImage(const sensor_msgs::ImagePtr& i) override { debug.push_back(i); }
};

// warp/mode layered: both virtual cameras in TF, the mode and the blend's
// figures in `state`, a full-size output, the debug image with the region
// drawn, and camera_info for the background layer (most of the frame). A
// reconfigure back to global takes effect from the next frame.
TEST(WrapperTest, LayeredModePublishesBothLayersAndSwitchesBackToGlobal) {
  DebugSink sink;
  steadiface::PipelineOptions po = Options();
  po.landmark_source =
      steadiface::LandmarkSource::kDlib;  // the region needs a face
  po.warp.mode = steadiface::WarpMode::kLayered;
  StabilizerWrapper w(po, WrapperOptions(), &sink);
  const int n = static_cast<int>(TestStream().images.size());
  Feed(&w, TestStream(), 0, n / 2);
  Sink gyro_sink;
  steadiface::PipelineOptions go = Options();
  go.stabilizer.gyro_only = true;
  go.landmark_source = steadiface::LandmarkSource::kNone;
  StabilizerWrapper gyro(go, WrapperOptions(), &gyro_sink);
  Feed(&gyro, TestStream(), 0, n / 2);
  ASSERT_EQ(sink.states.size(), static_cast<size_t>(n / 2));
  size_t background_tf = 0;
  for (const auto& t : sink.tf)
    background_tf += t.child_frame_id == "cam_stabilized_background";
  EXPECT_EQ(background_tf, sink.states.size());
  bool blended = false;
  for (size_t i = 0; i < sink.states.size(); ++i) {
    const auto& st = sink.states[i];
    EXPECT_EQ(st.warp_mode, "layered");
    ASSERT_TRUE(st.has_background_layer);
    EXPECT_EQ(st.folded_cells, 0u);
    EXPECT_GE(st.min_cell_ratio, 0.5);
    EXPECT_GE(st.layer_blend, 0.0);
    EXPECT_LE(st.layer_blend, 1.0);
    blended = blended || st.layer_blend > 0.5;
    // The output's intrinsics are the background layer's: a gyro-only run's.
    ASSERT_LT(i, gyro_sink.infos.size());
    EXPECT_EQ(sink.infos[i]->K[2], gyro_sink.infos[i]->K[2]);
    EXPECT_EQ(sink.infos[i]->K[5], gyro_sink.infos[i]->K[5]);
    EXPECT_EQ(sink.images[i]->width, TestStream().images[0]->width);
  }
  EXPECT_TRUE(blended);  // the face was found and the region applied
  ASSERT_FALSE(sink.debug.empty());
  ExpectAllFinite(sink);
  // Back to global at run time.
  w.RequestLayering(steadiface::WarpMode::kGlobal,
                    steadiface::LayeredWarpOptions());
  Feed(&w, TestStream(), n / 2, n);
  ASSERT_EQ(sink.states.size(), static_cast<size_t>(n));
  EXPECT_EQ(sink.states.back().warp_mode, "global");
  EXPECT_EQ(w.pipeline_options().warp.mode, steadiface::WarpMode::kGlobal);
  EXPECT_EQ(sink.errors.count("reconfigure"), 0u);
}

// warp/mode composite, switched on at run time from global: the mode and
// the composite's figures in `state` (finite, in range), camera_info for
// the background layer, the debug image with the matte; the face's pixels
// where the subject layer holds them.
TEST(WrapperTest, CompositeModeSwitchedOnAtRunTimePublishesItsState) {
  DebugSink sink;
  steadiface::PipelineOptions po = Options();
  po.landmark_source =
      steadiface::LandmarkSource::kDlib;  // the matte needs a face
  StabilizerWrapper w(po, WrapperOptions(), &sink);
  const int n = static_cast<int>(TestStream().images.size());
  Feed(&w, TestStream(), 0, n / 4);
  EXPECT_EQ(sink.states.back().warp_mode, "global");
  w.RequestLayering(steadiface::WarpMode::kComposite, po.warp.layered);
  Feed(&w, TestStream(), n / 4, n);
  ASSERT_EQ(sink.states.size(), static_cast<size_t>(n));
  EXPECT_EQ(w.pipeline_options().warp.mode, steadiface::WarpMode::kComposite);
  Sink gyro_sink;
  steadiface::PipelineOptions go = Options();
  go.stabilizer.gyro_only = true;
  go.landmark_source = steadiface::LandmarkSource::kNone;
  StabilizerWrapper gyro(go, WrapperOptions(), &gyro_sink);
  Feed(&gyro, TestStream());
  bool matted = false;
  for (int i = n / 4; i < n; ++i) {
    const auto& st = sink.states[i];
    EXPECT_EQ(st.warp_mode, "composite");
    ASSERT_TRUE(st.has_background_layer);
    EXPECT_GE(st.matte_mean, 0.0);
    EXPECT_LE(st.matte_mean, 1.0);
    EXPECT_GE(st.plate_share, 0.0);
    EXPECT_LE(st.plate_share + st.fallback_share, 1.0 + 1e-9);
    EXPECT_GE(st.plate_coverage, 0.0);
    EXPECT_LE(st.plate_coverage, 1.0);
    matted = matted || st.matte_mean > 0.05;
    EXPECT_EQ(sink.infos[i]->K[2], gyro_sink.infos[i]->K[2]);
    EXPECT_EQ(sink.images[i]->width, TestStream().images[0]->width);
  }
  EXPECT_TRUE(matted);  // the face was found and cut out
  ASSERT_FALSE(sink.debug.empty());
  EXPECT_EQ(sink.errors.count("reconfigure"), 0u);
  ExpectAllFinite(sink);
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

TEST(WrapperTest, ImuFaultsAreRejectedCountedAndHarmless) {
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  int k = 0;
  Feed(&w, TestStream(), 0, -1, [&](sensor_msgs::Imu* m) {
    ++k;
    if (k % 17 == 0) m->angular_velocity.x = kNaN;              // NaN
    if (k % 23 == 0) m->angular_velocity.y = INFINITY;          // Inf
    if (k % 29 == 0) m->header.stamp -= ros::Duration(0.0001);  // out of order
    if (k % 31 == 0) m->angular_velocity.z = 1e4;               // implausible
  });
  const WrapperStatus s = w.CurrentStatus();
  EXPECT_GT(s.counters.imu_rejected, 20u);
  EXPECT_GT(s.timeline.count(steadiface::SampleResult::kNonFinite), 10u);
  EXPECT_GT(s.timeline.count(steadiface::SampleResult::kImplausibleRate), 3u);
  EXPECT_EQ(sink.states.size(), TestStream().images.size());
  ExpectAllFinite(sink);
  EXPECT_GT(sink.warnings["imu_non_finite"], 0);
}

TEST(WrapperTest, ImuGapIsWarnedAndFramesExtrapolatedOrDropped) {
  for (steadiface::LateFramePolicy policy :
       {steadiface::LateFramePolicy::kExtrapolate,
        steadiface::LateFramePolicy::kDrop}) {
    Sink sink;
    WrapperOptions wo;
    wo.scheduler.late_frame_policy = policy;
    steadiface::PipelineOptions po = Options();
    po.imu.max_extrapolation_s = 0.05;
    po.rotation_source =
        steadiface::RotationSource::kImu;  // auto: the video fills gaps
    StabilizerWrapper w(po, wo, &sink);
    const Stream& st = TestStream();
    const ros::Time gap_from = st.images[20]->header.stamp,
                    gap_to = st.images[24]->header.stamp;
    Feed(&w, st, 0, -1, [&](sensor_msgs::Imu* m) {
      if (m->header.stamp > gap_from && m->header.stamp < gap_to)
        m->angular_velocity.x = kNaN;
    });
    const WrapperStatus s = w.CurrentStatus();
    EXPECT_GT(s.counters.imu_gaps, 0u);
    if (policy == steadiface::LateFramePolicy::kExtrapolate) {
      EXPECT_GT(s.counters.extrapolated + s.counters.dropped_no_gyro, 0u);
    } else {
      EXPECT_GT(s.counters.dropped_no_gyro, 0u);
      EXPECT_EQ(s.counters.extrapolated, 0u);
    }
    ExpectAllFinite(sink);
    // Stabilization resumes after the gap.
    EXPECT_GT(sink.states.size(), st.images.size() - 6);
  }
}

TEST(WrapperTest, NoImuPassesFramesThroughUnstabilized) {
  Sink sink;
  steadiface::PipelineOptions imu_only = Options();
  imu_only.rotation_source = steadiface::RotationSource::kImu;
  StabilizerWrapper w(imu_only, WrapperOptions(), &sink);
  const Stream& st = TestStream();
  for (const auto& img : st.images) {
    w.OnImage(img, st.info, img->header.stamp);
    w.OnTimer(img->header.stamp + ros::Duration(0.2));
  }
  w.Flush();
  EXPECT_EQ(sink.images.size(), st.images.size());
  EXPECT_TRUE(sink.states.empty());
  EXPECT_EQ(w.CurrentStatus().counters.passthrough, st.images.size());
  EXPECT_GT(sink.errors["no_imu"], 0);
  // Or dropped, when configured so.
  Sink sink2;
  WrapperOptions wo;
  wo.passthrough_without_imu = false;
  StabilizerWrapper w2(imu_only, wo, &sink2);
  for (const auto& img : st.images) w2.OnImage(img, st.info, img->header.stamp);
  w2.Flush();
  EXPECT_TRUE(sink2.images.empty());
  EXPECT_EQ(w2.CurrentStatus().counters.dropped_no_gyro, st.images.size());
}

// rotation_source visual: no IMU message at all, yet every frame is
// stabilized, and the real rotation the video gives turns between frames as
// the gyro's does (the walk preset's shake, at 320x180).
TEST(WrapperTest, WithoutAnImuTheVideoGivesTheRotation) {
  const Stream& st = TestStream();
  auto turns = [](const Sink& sink) {
    std::vector<Eigen::Quaterniond> q;
    for (const auto& s : sink.states) {
      q.emplace_back(s.real_rotation.w, s.real_rotation.x, s.real_rotation.y,
                     s.real_rotation.z);
    }
    std::vector<double> a;
    for (size_t i = 1; i < q.size(); ++i)
      a.push_back(q[i].angularDistance(q[i - 1]));
    return a;
  };
  Sink imu_sink;
  StabilizerWrapper imu(Options(), WrapperOptions(), &imu_sink);
  Feed(&imu, st);
  Sink sink;
  steadiface::PipelineOptions o = Options();
  o.rotation_source = steadiface::RotationSource::kVisual;
  StabilizerWrapper w(o, WrapperOptions(), &sink);
  for (const auto& img : st.images) {
    w.OnImage(img, st.info, img->header.stamp);
    w.OnTimer(img->header.stamp);
  }
  w.Flush();
  ASSERT_EQ(sink.states.size(), st.images.size());
  EXPECT_EQ(sink.images.size(), st.images.size());
  EXPECT_EQ(w.CurrentStatus().counters.passthrough, 0u);
  EXPECT_EQ(sink.errors["no_imu"], 0);
  EXPECT_EQ(w.CurrentStatus().rotation_source, "visual");
  EXPECT_TRUE(w.CurrentStatus().last_from_video);
  EXPECT_EQ(w.CurrentStatus().counters.from_video, st.images.size());
  EXPECT_TRUE(w.CurrentStatus().visual.valid);
  EXPECT_GE(w.CurrentStatus().visual.inliers, 20);
  ExpectAllFinite(sink);
  const std::vector<double> a = turns(sink), b = turns(imu_sink);
  ASSERT_EQ(a.size(), b.size());
  double err = 0.0, ref = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    err += (a[i] - b[i]) * (a[i] - b[i]);
    ref += b[i] * b[i];
  }
  // The frame-to-frame turn (0.026 rad RMS on walk) within a fifth of it
  // (measured: 0.0019 rad).
  std::cout << "[ frame-to-frame turn ] RMS " << std::sqrt(ref / b.size())
            << " rad (gyro), error of the video's " << std::sqrt(err / a.size())
            << " rad\n";
  EXPECT_LT(std::sqrt(err / a.size()), 0.2 * std::sqrt(ref / b.size()));
}

// rotation_source auto: with a healthy IMU exactly what imu gives; an IMU
// that drops out for 0.6 s mid-stream: every frame is still stabilized, the
// frames without IMU data by the video, and the virtual camera's largest
// per-frame turn at the two hand-overs is no larger than elsewhere.
TEST(WrapperTest, AutoBridgesAnImuDropoutWithTheVideo) {
  const Stream& st = TestStream();
  auto run = [&](steadiface::RotationSource source, bool dropout, Sink* sink) {
    steadiface::PipelineOptions o = Options();
    o.rotation_source = source;
    StabilizerWrapper w(o, WrapperOptions(), sink);
    const ros::Time t0 = st.images.front()->header.stamp;
    Feed(&w, st, 0, -1, [&](sensor_msgs::Imu* m) {
      const double t = (m->header.stamp - t0).toSec();
      if (dropout && t > 0.6 && t < 1.2)
        m->angular_velocity.x = kNaN;  // lost: rejected
    });
    return w.CurrentStatus();
  };
  Sink imu, healthy;
  run(steadiface::RotationSource::kImu, false, &imu);
  const WrapperStatus h =
      run(steadiface::RotationSource::kAuto, false, &healthy);
  ASSERT_EQ(healthy.states.size(), imu.states.size());
  for (size_t i = 0; i < imu.states.size(); ++i) {
    EXPECT_EQ(healthy.states[i].virtual_rotation,
              imu.states[i].virtual_rotation)
        << i;
    EXPECT_EQ(healthy.states[i].principal_offset,
              imu.states[i].principal_offset)
        << i;
  }
  EXPECT_EQ(h.counters.from_video, 0u);
  Sink gap;
  const WrapperStatus g = run(steadiface::RotationSource::kAuto, true, &gap);
  EXPECT_EQ(gap.states.size(), st.images.size())
      << "a frame was not stabilized";
  EXPECT_EQ(g.counters.passthrough, 0u);
  EXPECT_GT(g.counters.from_video, 10u);
  EXPECT_LT(g.counters.from_video, st.images.size() / 2);
  ExpectAllFinite(gap);
  // The virtual camera's turn from frame to frame, and where the source
  // changed.
  std::vector<double> turn;
  for (size_t i = 1; i < gap.states.size(); ++i) {
    const auto& a = gap.states[i - 1].virtual_rotation;
    const auto& b = gap.states[i].virtual_rotation;
    turn.push_back(
        Eigen::Quaterniond(a.w, a.x, a.y, a.z)
            .angularDistance(Eigen::Quaterniond(b.w, b.x, b.y, b.z)));
  }
  double steady = 0.0, handover = 0.0;
  for (size_t i = 0; i < turn.size(); ++i) {
    const bool switched =
        gap.states[i + 1].rotation_source != gap.states[i].rotation_source;
    (switched ? handover : steady) =
        std::max(switched ? handover : steady, turn[i]);
  }
  std::cout << "[ IMU dropout ] " << g.counters.from_video << " of "
            << gap.states.size()
            << " frames rotated by the video; largest virtual turn per frame: "
            << steady << " rad elsewhere, " << handover
            << " rad at the hand-overs\n";
  EXPECT_GT(handover, 0.0);
  EXPECT_LE(handover, std::max(steady, 1e-9) * 1.0 + 1e-9);
}

sensor_msgs::ImagePtr Copy(const sensor_msgs::ImagePtr& m) {
  return sensor_msgs::ImagePtr(new sensor_msgs::Image(*m));
}

TEST(WrapperTest, BadImagesAreDroppedWithAReason) {
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  const Stream& st = TestStream();
  Feed(&w, st, 0, -1, {}, [&](int i) -> sensor_msgs::ImagePtr {
    sensor_msgs::ImagePtr m = Copy(st.images[i]);
    switch (i) {
      case 5:
        m->encoding = "no_such_encoding";
        break;
      case 6:
        m->width = m->height = 0;
        m->data.clear();
        break;
      case 7:
        m->data.resize(m->data.size() / 2);
        break;  // step * height != size
      case 8:
        m->step = 10;
        break;  // step < width * 3
      case 9:
        m->width = 100;
        m->step = 300;
        m->data.resize(300 * m->height);
        break;  // != camera_info
      case 10:
        m->encoding = "mono16";
        m->step = m->width * 2;
        m->data.assign(m->step * m->height, 0x40);
        break;  // converted by cv_bridge
      case 11:
        m->encoding = "32FC1";
        m->step = m->width * 4;
        m->data.assign(m->step * m->height, 0);
        break;  // not cleanly: refused
      default:
        break;
    }
    return m;
  });
  const WrapperStatus s = w.CurrentStatus();
  EXPECT_EQ(s.counters.dropped_bad_image, 6u);  // 5, 6, 7, 8, 9, 11
  EXPECT_EQ(sink.states.size(), st.images.size() - 6);
  EXPECT_GT(sink.errors["image"], 0);
  EXPECT_GT(sink.errors["image_size"], 0);
  ExpectAllFinite(sink);
}

TEST(WrapperTest, CameraInfoMissingOrChangingIsHandled) {
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  const Stream& st = TestStream();
  size_t g = 0;
  sensor_msgs::CameraInfoPtr uncal(new sensor_msgs::CameraInfo(*st.info));
  uncal->K.fill(0.0);
  for (size_t i = 0; i < st.images.size(); ++i) {
    while (g < st.imu.size() &&
           st.imu[g].header.stamp <=
               st.images[i]->header.stamp + ros::Duration(0.03)) {
      w.OnImu(st.imu[g++]);
    }
    if (i == 3) {
      w.OnImage(st.images[i], nullptr,
                st.images[i]->header.stamp);  // no camera_info
    } else if (i == 4) {
      w.OnImage(st.images[i], uncal,
                st.images[i]->header.stamp);  // uncalibrated
    } else if (i >= 30) {
      // Resolution change mid-stream: half-size frames with matching info.
      sensor_msgs::CameraInfoPtr half(new sensor_msgs::CameraInfo(*st.info));
      half->width /= 2;
      half->height /= 2;
      for (int k : {0, 2, 4, 5}) half->K[k] /= 2;
      cv::Mat small;
      cv::resize(cv_bridge::toCvShare(st.images[i])->image, small,
                 cv::Size(half->width, half->height));
      sensor_msgs::ImagePtr m =
          cv_bridge::CvImage(st.images[i]->header, "bgr8", small).toImageMsg();
      w.OnImage(m, half, m->header.stamp);
    } else {
      w.OnImage(st.images[i], st.info, st.images[i]->header.stamp);
    }
    w.OnTimer(st.images[i]->header.stamp);
  }
  w.Flush();
  const WrapperStatus s = w.CurrentStatus();
  EXPECT_EQ(s.counters.dropped_bad_info, 2u);
  EXPECT_EQ(s.counters.rebuilds, 1u);
  EXPECT_EQ(sink.images.back()->width, st.info->width / 2);
  EXPECT_EQ(sink.infos.back()->width, st.info->width / 2);
  EXPECT_EQ(sink.states.size(), st.images.size() - 2);
  ExpectAllFinite(sink);
}

TEST(WrapperTest, BurstsBeyondTheQueueAreBoundedAndCounted) {
  Sink sink;
  WrapperOptions wo;
  wo.scheduler.frame_queue_size = 5;
  StabilizerWrapper w(Options(), wo, &sink);
  const Stream& st = TestStream();
  // A burst of 30 frames before any IMU arrives, and no time passing.
  for (int i = 0; i < 30; ++i) w.OnImage(st.images[i], st.info, ros::Time(1.0));
  EXPECT_EQ(w.CurrentStatus().counters.dropped_queue_full, 25u);
  for (const auto& m : st.imu) w.OnImu(m);
  w.Flush();
  EXPECT_EQ(sink.states.size(), 5u);
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
}  // namespace steadiface_ros

namespace steadiface_ros {
namespace {

// The view (output/crop dynamic, output/horizon level): each frame's state
// carries its crop and camera_info the matching focal length; the horizon
// is levelled from the messages' accelerometer, and without one the state
// says why it is not.
TEST(WrapperTest, TheViewReachesTheStateAndCameraInfo) {
  steadiface::PipelineOptions o = Options();
  o.crop.mode = steadiface::CropMode::kDynamic;
  o.horizon.mode = steadiface::HorizonMode::kLevel;
  Sink sink;
  StabilizerWrapper w(o, WrapperOptions(), &sink);
  Feed(&w, TestStream());
  ASSERT_EQ(sink.states.size(), TestStream().images.size());
  ASSERT_EQ(sink.infos.size(), sink.states.size());
  const double fx0 =
      sink.infos.front()->K[0] * (1.0 - 2.0 * sink.states.front().crop_ratio);
  for (size_t i = 0; i < sink.states.size(); ++i) {
    const steadiface::StabilizerState& s = sink.states[i];
    EXPECT_EQ(s.crop_mode, "dynamic");
    EXPECT_GE(s.crop_ratio, 0.0);
    EXPECT_LE(s.crop_ratio, 0.15);
    // fx in output pixels times the kept width is the same on every frame.
    EXPECT_NEAR(sink.infos[i]->K[0] * (1.0 - 2.0 * s.crop_ratio), fx0,
                1e-6 * fx0)
        << i;
  }
  const WrapperStatus st = w.CurrentStatus();
  EXPECT_EQ(st.horizon_mode, "level");
  EXPECT_TRUE(st.horizon.active);
  // The walk's bob (2.6 m/s^2 at 1.8 Hz) puts many readings beyond 10 % of
  // 1 g: they are left out.
  EXPECT_GT(st.accel_accepted, 50u);
  EXPECT_GT(st.accel_rejected, 0u);
  EXPECT_LT(std::abs(st.horizon.output_roll_rad), 0.02);  // the walk is level
  ExpectAllFinite(sink);

  // The same without accelerometer readings: the roll is left alone.
  Sink bare;
  StabilizerWrapper w2(o, WrapperOptions(), &bare);
  Feed(&w2, TestStream(), 0, -1, [](sensor_msgs::Imu* m) {
    m->linear_acceleration.x = m->linear_acceleration.y =
        m->linear_acceleration.z = 0.0;
  });
  EXPECT_FALSE(w2.CurrentStatus().horizon.active);
  EXPECT_EQ(w2.CurrentStatus().horizon.inactive_reason, "no accelerometer");
  EXPECT_EQ(w2.CurrentStatus().counters.accel_in, 0u);
  EXPECT_EQ(bare.states.size(), TestStream().images.size());
}

}  // namespace
}  // namespace steadiface_ros
