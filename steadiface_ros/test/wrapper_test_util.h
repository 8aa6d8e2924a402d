#pragma once

// The wrapper tests' fixtures: a recording sink, a short simulated stream as
// messages, the options they run with, and checks every test shares.

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

#include "steadiface_core/sim/simulator.h"
#include "steadiface_ros/stabilizer_wrapper.h"
#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {
namespace wrapper_test {

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

inline const Stream& TestStream() {
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

inline steadiface::PipelineOptions Options() {
  steadiface::PipelineOptions o;
  o.shutter.readout_time_s = TestStream().readout;
  o.landmark_source =
      steadiface::LandmarkSource::kNone;  // fast; faces are tested elsewhere
  return o;
}

// Feeds the stream in time order (IMU up to each frame's last row first).
inline void Feed(StabilizerWrapper* w, const Stream& s, int from = 0, int to = -1,
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

inline void ExpectAllFinite(const Sink& sink) {
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

// A sink that also keeps the debug images.
struct DebugSink : public Sink {
  std::vector<sensor_msgs::ImagePtr> debug;
  bool WantsDebugImage() const override { return true; }
  void PublishDebugImage(const sensor_msgs::ImagePtr& i) override { debug.push_back(i); }
};

inline sensor_msgs::ImagePtr Copy(const sensor_msgs::ImagePtr& m) {
  return sensor_msgs::ImagePtr(new sensor_msgs::Image(*m));
}

}  // namespace wrapper_test
}  // namespace steadiface_ros
