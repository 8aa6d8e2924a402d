// RunSimulation (steadiface_simulate's run): a short recording read back
// has every frame with its camera_info, the IMU at its rate in the IMU's
// mounting, every sample up to a frame's last row before that frame, and a
// truth row per frame.
#include "steadiface_simulate/simulate_run.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include "steadiface_core/sim/truth_file.h"

namespace steadiface_simulate {
namespace {

TEST(SimulateRunTest, ARecordingReadBackIsTheSimulation) {
  char tmpl[] = "/tmp/steadiface_simulate_run_test_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  SimulateOptions o;
  o.preset = "pan";
  o.out = dir + "/pan.bag";
  o.data = STEADIFACE_TEST_DATA_DIR;
  o.sim.duration_s = 0.5;
  o.sim.width = 160;
  o.sim.height = 90;
  o.readout = 0.02;
  o.mono = true;
  // Mounted turned 90 degrees about z: the gyro's x is the camera's y.
  o.R_imu_cam = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  ASSERT_EQ(RunSimulation(o), 0);
  // The same simulation, made directly: its gyro in camera axes.
  steadiface::sim::SimulationSettings settings;
  settings.preset = o.preset;
  settings.data_dir = o.data;
  settings.base = o.sim;
  settings.readout_s = o.readout;
  settings.epoch_s = o.epoch;
  steadiface::sim::SimulatorOptions so;
  std::unique_ptr<steadiface::sim::Simulator> sim;
  ASSERT_TRUE(steadiface::sim::MakeSimulatorOptions(settings, &so).ok());
  ASSERT_TRUE(steadiface::sim::Simulator::Create(so, &sim).ok());
  rosbag::Bag bag(o.out, rosbag::bagmode::Read);
  int images = 0, infos = 0;
  size_t imus = 0;
  ros::Time last_imu;
  double worst_gyro = 0.0;  // recorded vs R_imu_cam * the simulator's [rad/s]
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (auto img = m.instantiate<sensor_msgs::Image>()) {
      ++images;
      EXPECT_EQ(img->encoding, "mono8");
      EXPECT_EQ(img->width, 160u);
      // Every IMU sample so far is at most the last row's time.
      EXPECT_LE(last_imu, img->header.stamp + ros::Duration(0.02));
    } else if (auto imu = m.instantiate<sensor_msgs::Imu>()) {
      ASSERT_LT(imus, sim->imu().size());
      const Eigen::Vector3d w(imu->angular_velocity.x, imu->angular_velocity.y,
                              imu->angular_velocity.z);
      worst_gyro = std::max(
          worst_gyro, (w - o.R_imu_cam * sim->imu()[imus].angular_velocity).norm());
      ++imus;
      last_imu = imu->header.stamp;
      EXPECT_EQ(imu->orientation_covariance[0], -1);
    } else if (m.getTopic() == "/camera/camera_info") {
      ++infos;
    }
  }
  EXPECT_EQ(images, 15);  // 0.5 s at 30 fps
  EXPECT_EQ(infos, images);
  EXPECT_EQ(imus, sim->imu().size());
  EXPECT_GT(imus, 100u);  // 0.5 s at 200 Hz, and before the first and after the last row
  EXPECT_LT(worst_gyro, 1e-9);
  std::ifstream truth(o.out + ".truth.csv");
  std::string line;
  int rows = 0;
  while (std::getline(truth, line)) rows += !line.empty() && line[0] != '#' ? 1 : 0;
  EXPECT_EQ(rows, images + 1);  // a header and a row per frame
  std::remove(o.out.c_str());
  std::remove((o.out + ".truth.csv").c_str());
  rmdir(dir.c_str());
}

// Per topic: the messages and the stamps of the IMU's [s from the epoch].
struct Counts {
  int images = 0, imus = 0;
  std::vector<double> imu_t;
};

Counts Read(const std::string& path, double epoch) {
  Counts c;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (m.instantiate<sensor_msgs::Image>()) ++c.images;
    if (auto imu = m.instantiate<sensor_msgs::Imu>()) {
      ++c.imus;
      c.imu_t.push_back(imu->header.stamp.toSec() - epoch);
    }
  }
  return c;
}

// A camera without an IMU (--imu-topic none), and an IMU that drops out
// from 3 s to 5 s (the dropout preset): the frames are all there; the first
// has no IMU message, the second none in the gap and every other one.
TEST(SimulateRunTest, NoImuAndAnImuDropout) {
  char tmpl[] = "/tmp/steadiface_simulate_run_test_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  SimulateOptions o;
  o.preset = "dropout";
  o.data = STEADIFACE_TEST_DATA_DIR;
  o.sim.width = 96;
  o.sim.height = 54;
  o.epoch = 100.0;
  o.out = dir + "/dropout.bag";
  ASSERT_EQ(RunSimulation(o), 0);
  const Counts gap = Read(o.out, o.epoch);
  EXPECT_EQ(gap.images, 210);  // the preset's 7 s at 30 fps
  int in_gap = 0, before = 0, after = 0;
  for (double t : gap.imu_t) {
    in_gap += t > 3.001 && t < 4.999;
    before += t < 3.0;
    after += t > 5.0;
  }
  EXPECT_EQ(in_gap, 0);
  EXPECT_NEAR(before, 600, 2);  // 200 Hz
  EXPECT_GT(after, 400);
  o.imu_topic = "none";
  o.out = dir + "/no_imu.bag";
  ASSERT_EQ(RunSimulation(o), 0);
  const Counts none = Read(o.out, o.epoch);
  EXPECT_EQ(none.images, 210);
  EXPECT_EQ(none.imus, 0);
  for (const std::string& f : {dir + "/dropout.bag", dir + "/no_imu.bag"}) {
    std::remove(f.c_str());
    std::remove((f + ".truth.csv").c_str());
  }
  rmdir(dir.c_str());
}

}  // namespace
}  // namespace steadiface_simulate
