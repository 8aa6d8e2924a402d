#pragma once

#include <memory>
#include <mutex>

#include <boost/thread/recursive_mutex.hpp>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <dynamic_reconfigure/server.h>
#include <image_transport/image_transport.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Imu.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "steadiface/SteadifaceConfig.h"
#include "steadiface_ros/camera_info_source.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace steadiface_ros {

/// The live ROS front end of StabilizerWrapper, shared by the nodelet and
/// the node. Construction order: parameters, then dynamic_reconfigure (its
/// own mutex), then publishers, then subscribers.
///
/// Threading model: every subscription callback and the timer run on the
/// node handle's callback queue. The nodelet uses the single-threaded
/// queue, so image, IMU and landmark callbacks never run concurrently; the
/// IMU is never subscribed lazily (queue 2000) and a frame waits in a
/// bounded queue until the gyro covers its last row (or max_gyro_wait runs
/// out). dynamic_reconfigure runs its callback on its own thread and only
/// stores the new options (under the wrapper's mutex); the diagnostic
/// updater runs from the timer. Unloading: the destructor shuts down the
/// subscribers and timer first, then the rest.
class StabilizerRos : public OutputSink {
 public:
  /// `nh` is the node (public) handle for topics, `pnh` the private one for
  /// parameters. On a parameter error, logs it and stays inert (ok() false).
  StabilizerRos(ros::NodeHandle nh, ros::NodeHandle pnh, const std::string& name);
  ~StabilizerRos() override;

  bool ok() const { return ok_; }

  // OutputSink.
  void PublishImage(const sensor_msgs::ImagePtr& image,
                    const sensor_msgs::CameraInfoPtr& info) override;
  void PublishLandmarks(const steadiface::FaceLandmarks& msg) override;
  void PublishState(const steadiface::StabilizerState& msg) override;
  void PublishTf(const std::vector<geometry_msgs::TransformStamped>& tf) override;
  void PublishHeadTarget(const geometry_msgs::PointStamped& p) override;
  bool WantsMarkers() const override;
  void PublishMarkers(const visualization_msgs::MarkerArray& m) override;
  bool WantsDebugImage() const override;
  void PublishDebugImage(const sensor_msgs::ImagePtr& image) override;
  void Warn(const std::string& key, const std::string& text) override;
  void Error(const std::string& key, const std::string& text) override;
  void OnTimeJump() override;
  ros::Time Now() const override { return ros::Time::now(); }

 private:
  // The constructor's steps, in order: parameters (false: invalid, the node
  // stays idle), reconfigure, publishers, diagnostics, subscribers.
  bool LoadParameters();
  void StartReconfigure();
  void Advertise();
  void StartDiagnostics();
  std::string Subscribe(bool* builtin_compressed);
  void OnImage(const sensor_msgs::ImageConstPtr& image,
               const sensor_msgs::CameraInfoConstPtr& info);
  // With camera_info_url, or compressed images without the
  // image_transport plugin: images and camera_info subscribed separately; a
  // camera_info message within 0.5 s of the image wins over the file.
  void OnImageOnly(const sensor_msgs::ImageConstPtr& image);
  void OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg);
  void OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& info);
  void OnImu(const sensor_msgs::ImuConstPtr& msg);
  void OnLandmarks(const steadiface::FaceLandmarksConstPtr& msg);
  void OnTimer(const ros::TimerEvent& e);
  void OnReconfigure(steadiface::SteadifaceConfig& config, uint32_t level);
  bool LookupExtrinsic(const std::string& imu_frame, const std::string& camera_frame,
                       Eigen::Quaterniond* q);

  void DiagGyro(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagRotationSource(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagView(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagFace(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagSolver(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagFrames(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagProtrusion(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagGyroVideo(diagnostic_updater::DiagnosticStatusWrapper& s);
  void DiagExtrinsics(diagnostic_updater::DiagnosticStatusWrapper& s);

  ros::NodeHandle nh_, pnh_;
  std::string name_;
  bool ok_ = false;
  steadiface::PipelineOptions pipeline_options_;
  WrapperOptions wrapper_options_;
  std::unique_ptr<StabilizerWrapper> wrapper_;

  boost::recursive_mutex reconfigure_mutex_;  // dynamic_reconfigure wants boost
  std::unique_ptr<dynamic_reconfigure::Server<steadiface::SteadifaceConfig>> reconfigure_;

  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::CameraPublisher image_pub_;
  image_transport::Publisher debug_pub_;
  ros::Publisher landmarks_pub_, state_pub_, head_target_pub_, frusta_pub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;

  image_transport::CameraSubscriber image_sub_;
  std::unique_ptr<CameraInfoSource> info_source_;
  image_transport::Subscriber image_only_sub_;  // camera_info_url mode
  ros::Subscriber info_sub_;                    // camera_info_url mode
  ros::Subscriber compressed_sub_;  // built-in jpeg/png decoder (no plugin)
  uint64_t decode_failures_ = 0;
  sensor_msgs::CameraInfoConstPtr latest_info_;
  ros::Subscriber imu_sub_, landmarks_sub_;
  ros::Timer timer_;

  std::unique_ptr<diagnostic_updater::Updater> updater_;
  double image_min_rate_ = 0.0, image_max_rate_ = 1e9, imu_min_rate_ = 0.0, imu_max_rate_ = 1e9;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> image_freq_, imu_freq_;
  ros::WallTime last_imu_wall_;
  bool imu_seen_ = false;
  uint64_t reported_drops_ = 0, reported_fallbacks_ = 0, reported_solver_failures_ = 0;
};

}  // namespace steadiface_ros
