// camera_info_url: URL resolution, the calibration file formats ROS camera
// drivers use (camera_calibration YAML and INI), the message-wins rule, and
// the example overlays of config/examples (each loads and states what its
// README line says).
#include "steadiface_ros/camera_info_source.h"

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <camera_calibration_parsers/parse.h>
#include <gtest/gtest.h>

#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/params.h"

namespace steadiface_ros {
namespace {

const std::string kConfigDir = STEADIFACE_CONFIG_DIR;

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/steadiface_cis_" + name;
}

sensor_msgs::CameraInfo SomeInfo(int w, int h) {
  sensor_msgs::CameraInfo ci;
  ci.width = w;
  ci.height = h;
  ci.distortion_model = "plumb_bob";
  ci.D = {0.1, -0.05, 0.001, 0.002, 0.0};
  ci.K = {500.0, 0.0, 320.5, 0.0, 498.0, 240.25, 0.0, 0.0, 1.0};
  ci.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  ci.P = {500.0, 0.0, 320.5, 0.0, 0.0, 498.0, 240.25, 0.0, 0.0, 0.0, 1.0, 0.0};
  return ci;
}

sensor_msgs::Image Image(int w, int h, double stamp) {
  sensor_msgs::Image im;
  im.width = w;
  im.height = h;
  im.encoding = "mono8";
  im.step = w;
  im.data.assign(static_cast<size_t>(w) * h, 0);
  im.header.stamp.fromSec(stamp);
  im.header.frame_id = "cam0";
  return im;
}

TEST(CameraInfoUrlTest, ResolvesFilePackageAndPlainPaths) {
  std::string p;
  ASSERT_TRUE(ResolveCameraInfoUrl("file:///tmp/a.yaml", &p).ok());
  EXPECT_EQ(p, "/tmp/a.yaml");
  ASSERT_TRUE(ResolveCameraInfoUrl("relative/b.ini", &p).ok());
  EXPECT_EQ(p, "relative/b.ini");
  // package:// needs ROS_PACKAGE_PATH; the catkin test environment has it.
  const steadiface::Status s = ResolveCameraInfoUrl(
      "package://steadiface/config/examples/euroc_cam0_calibration.yaml", &p);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(std::ifstream(p).good()) << p;
  EXPECT_NE(p.find("config/examples/euroc_cam0_calibration.yaml"),
            std::string::npos);

  steadiface::Status bad =
      ResolveCameraInfoUrl("http://example.org/cam.yaml", &p);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("unsupported scheme"), std::string::npos)
      << bad.message();
  bad = ResolveCameraInfoUrl("package://no_such_package_xyz/cam.yaml", &p);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("no_such_package_xyz"), std::string::npos)
      << bad.message();
  EXPECT_FALSE(ResolveCameraInfoUrl("package://steadiface", &p).ok());
}

TEST(CameraInfoUrlTest, ReadsYamlAndIniAsCameraCalibrationWritesThem) {
  const sensor_msgs::CameraInfo truth = SomeInfo(640, 480);
  for (const std::string ext : {"yaml", "ini"}) {
    const std::string path = TempPath("cam." + ext);
    ASSERT_TRUE(
        camera_calibration_parsers::writeCalibration(path, "cam", truth))
        << ext;
    sensor_msgs::CameraInfo got;
    const steadiface::Status s = LoadCameraInfoUrl("file://" + path, &got);
    ASSERT_TRUE(s.ok()) << ext << ": " << s.message();
    EXPECT_EQ(got.width, 640u);
    EXPECT_EQ(got.height, 480u);
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(got.K[i], truth.K[i], 1e-9) << ext << " K" << i;
    ASSERT_EQ(got.D.size(), truth.D.size()) << ext;
    for (size_t i = 0; i < truth.D.size(); ++i)
      EXPECT_NEAR(got.D[i], truth.D[i], 1e-9);
    // And the core accepts it as it accepts a camera_info message.
    steadiface::CameraIntrinsics k;
    ASSERT_TRUE(ToCameraIntrinsics(got, &k).ok());
    EXPECT_DOUBLE_EQ(k.fx, 500.0);
    EXPECT_DOUBLE_EQ(k.cy, 240.25);
    std::remove(path.c_str());
  }
}

TEST(CameraInfoUrlTest, RefusesMissingAndMalformedFilesNamingThem) {
  sensor_msgs::CameraInfo ci;
  steadiface::Status s =
      LoadCameraInfoUrl("file:///nonexistent/dir/cam.yaml", &ci);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/nonexistent/dir/cam.yaml"), std::string::npos)
      << s.message();

  const std::string garbage = TempPath("garbage.yaml");
  std::ofstream(garbage) << "this: [is, not, a calibration\n";
  s = LoadCameraInfoUrl(garbage, &ci);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("calibration"), std::string::npos) << s.message();

  // Parses, but without a camera matrix it cannot give intrinsics.
  const std::string empty_k = TempPath("empty_k.yaml");
  sensor_msgs::CameraInfo zero = SomeInfo(640, 480);
  zero.K = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  ASSERT_TRUE(
      camera_calibration_parsers::writeCalibration(empty_k, "cam", zero));
  s = LoadCameraInfoUrl(empty_k, &ci);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("fx"), std::string::npos) << s.message();
  std::remove(garbage.c_str());
  std::remove(empty_k.c_str());
}

TEST(CameraInfoSourceTest, AMessageWinsTheFileFillsInAndTheChoiceIsLoggedOnce) {
  const std::string path = TempPath("src.yaml");
  ASSERT_TRUE(camera_calibration_parsers::writeCalibration(path, "cam",
                                                           SomeInfo(64, 48)));
  std::vector<std::string> log;
  int errors = 0;
  CameraInfoSource src([&](bool is_error, const std::string& t) {
    log.push_back(t);
    errors += is_error;
  });
  ASSERT_TRUE(src.Load("file://" + path).ok());
  ASSERT_TRUE(src.has_file_info());

  // No message: the file's, stamped and framed as the image.
  for (int i = 0; i < 3; ++i) {
    const sensor_msgs::Image im = Image(64, 48, 100.0 + i);
    sensor_msgs::CameraInfoConstPtr got = src.Select(im, nullptr);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->header.stamp, im.header.stamp);
    EXPECT_EQ(got->header.frame_id, "cam0");
    EXPECT_DOUBLE_EQ(got->K[0], 500.0);
  }
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("camera_info_url"), std::string::npos) << log[0];

  // A message arrives: it wins.
  sensor_msgs::CameraInfoPtr msg(new sensor_msgs::CameraInfo(SomeInfo(64, 48)));
  msg->K[0] = 321.0;
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(src.Select(Image(64, 48, 200.0 + i), msg)->K[0], 321.0);
  }
  ASSERT_EQ(log.size(), 2u);
  EXPECT_NE(log[1].find("win"), std::string::npos) << log[1];

  // The file's size does not match the images: refused, one error.
  for (int i = 0; i < 3; ++i)
    EXPECT_FALSE(src.Select(Image(80, 48, 300.0 + i), nullptr));
  EXPECT_EQ(errors, 1);
  EXPECT_NE(log.back().find("64x48"), std::string::npos) << log.back();
  std::remove(path.c_str());
}

TEST(CameraInfoSourceTest, WithoutAUrlOnlyMessagesGiveIntrinsics) {
  CameraInfoSource src(nullptr);
  ASSERT_TRUE(src.Load("").ok());
  EXPECT_FALSE(src.has_file_info());
  EXPECT_FALSE(src.Select(Image(64, 48, 1.0), nullptr));
  sensor_msgs::CameraInfoConstPtr msg(
      new sensor_msgs::CameraInfo(SomeInfo(64, 48)));
  EXPECT_EQ(src.Select(Image(64, 48, 1.0), msg), msg);
}

// Each overlay of config/examples loads on top of default.yaml (as the
// launch file and steadiface_bag --params load it) and states its layout.
struct Loaded {
  steadiface::PipelineOptions po;
  WrapperOptions wo;
};
Loaded LoadExample(const std::string& name) {
  std::unique_ptr<ParamSource> p;
  Loaded l;
  const steadiface::Status s = YamlParams(
      {kConfigDir + "/default.yaml", kConfigDir + "/examples/" + name}, &p);
  EXPECT_TRUE(s.ok()) << name << ": " << s.message();
  if (!s.ok()) return l;
  const steadiface::Status ls = LoadOptions(*p, &l.po, &l.wo);
  EXPECT_TRUE(ls.ok()) << name << ": " << ls.message();
  return l;
}

TEST(ExampleOverlaysTest,
     EurocCam0IsGlobalShutterMonoWithARotatedImuAndIntrinsicsFromAFile) {
  const Loaded l = LoadExample("euroc_cam0.yaml");
  EXPECT_EQ(l.po.shutter.readout_time_s, 0.0);
  EXPECT_FALSE(l.wo.imu_extrinsics_from_tf);
  // R_cam_imu is the inverse of the rotation block of EuRoC's T_BS.
  const Eigen::Matrix3d R_BS =
      (Eigen::Matrix3d() << 0.0148655429818, -0.999880929698, 0.00414029679422,
       0.999557249008, 0.0149672133247, 0.025715529948, -0.0257744366974,
       0.00375618835797, 0.999660727178)
          .finished();
  const Eigen::Matrix3d R = l.po.imu.R_cam_imu.toRotationMatrix();
  EXPECT_LT((R - R_BS.transpose()).norm(), 1e-6) << R;
  // The IMU's x axis is (about) the camera's -y: a quarter turn, not identity.
  EXPECT_GT(Eigen::AngleAxisd(l.po.imu.R_cam_imu).angle(), 1.5);

  sensor_msgs::CameraInfo ci;
  const steadiface::Status s = LoadCameraInfoUrl(l.wo.camera_info_url, &ci);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(ci.width, 752u);
  EXPECT_EQ(ci.height, 480u);
  EXPECT_DOUBLE_EQ(ci.K[0], 458.654);
  EXPECT_DOUBLE_EQ(ci.K[4], 457.296);
  EXPECT_DOUBLE_EQ(ci.K[2], 367.215);
  EXPECT_DOUBLE_EQ(ci.K[5], 248.375);
  ASSERT_GE(ci.D.size(), 4u);
  EXPECT_DOUBLE_EQ(ci.D[0], -0.28340811);
  steadiface::CameraIntrinsics k;
  EXPECT_TRUE(ToCameraIntrinsics(ci, &k).ok());
  EXPECT_EQ(k.distortion, steadiface::DistortionModel::kPlumbBob);
}

TEST(ExampleOverlaysTest,
     RealsenseD435iTakesTheGyroMountingFromTfWithARollingShutter) {
  const Loaded l = LoadExample("realsense_d435i.yaml");
  EXPECT_TRUE(l.wo.imu_extrinsics_from_tf);
  EXPECT_GT(l.po.shutter.readout_time_s, 0.005);
  EXPECT_TRUE(
      l.wo.camera_info_url.empty());  // the driver publishes camera_info
}

TEST(ExampleOverlaysTest, LayeredSwitchesOnlyTheWarpMode) {
  const Loaded l = LoadExample("layered.yaml");
  const Loaded d = LoadExample("../default.yaml");
  EXPECT_EQ(l.po.warp.mode, steadiface::WarpMode::kLayered);
  EXPECT_EQ(d.po.warp.mode, steadiface::WarpMode::kGlobal);
  EXPECT_TRUE(steadiface::SameLayering(steadiface::WarpMode::kLayered, d.po.warp.layered,
                                       l.po.warp));
}

TEST(ExampleOverlaysTest, NoImuTakesTheRotationFromTheVideoAndChangesNothingElse) {
  const Loaded n = LoadExample("no_imu.yaml");
  const Loaded d = LoadExample("../default.yaml");
  EXPECT_EQ(n.po.rotation_source, steadiface::RotationSource::kVisual);
  EXPECT_EQ(d.po.rotation_source, steadiface::RotationSource::kAuto);
  EXPECT_EQ(n.po.warp.mode, d.po.warp.mode);
  EXPECT_EQ(n.po.shutter.readout_time_s, d.po.shutter.readout_time_s);
}

TEST(ExampleOverlaysTest, CompositeSwitchesOnlyTheWarpMode) {
  const Loaded c = LoadExample("composite.yaml");
  const Loaded d = LoadExample("../default.yaml");
  EXPECT_EQ(c.po.warp.mode, steadiface::WarpMode::kComposite);
  EXPECT_TRUE(steadiface::SameLayering(steadiface::WarpMode::kComposite, d.po.warp.layered,
                                       c.po.warp));
  EXPECT_EQ(c.po.composite.matte.scale, d.po.composite.matte.scale);
  EXPECT_EQ(c.po.composite.plate.max_age_s, d.po.composite.plate.max_age_s);
}

TEST(ExampleOverlaysTest, PhoneFrontCameraIsAHalfTurnAboutTheOpticalAxis) {
  const Loaded l = LoadExample("phone.yaml");
  EXPECT_FALSE(l.wo.imu_extrinsics_from_tf);
  EXPECT_GT(l.po.shutter.readout_time_s, 0.005);
  // Android x (right) -> camera -x, y (up) -> camera -y, z (to the user) -> +z.
  const Eigen::Vector3d x = l.po.imu.R_cam_imu * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y = l.po.imu.R_cam_imu * Eigen::Vector3d::UnitY();
  const Eigen::Vector3d z = l.po.imu.R_cam_imu * Eigen::Vector3d::UnitZ();
  EXPECT_LT((x - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-9);
  EXPECT_LT((y - Eigen::Vector3d(0, -1, 0)).norm(), 1e-9);
  EXPECT_LT((z - Eigen::Vector3d(0, 0, 1)).norm(), 1e-9);
}

}  // namespace
}  // namespace steadiface_ros

namespace steadiface_ros {
namespace {

TEST(ExampleOverlaysTest, ViewTurnsOnTheDynamicCropAndTheLevelHorizon) {
  const Loaded l = LoadExample("view.yaml");
  EXPECT_EQ(l.po.crop.mode, steadiface::CropMode::kDynamic);
  EXPECT_EQ(l.po.horizon.mode, steadiface::HorizonMode::kLevel);
  EXPECT_DOUBLE_EQ(l.po.warp.output.crop_ratio, 0.15);  // the tightest, unchanged
}

}  // namespace
}  // namespace steadiface_ros
