#pragma once

#include <functional>
#include <string>

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "steadiface_core/common/status.h"

namespace steadiface_ros {

/// `camera_info_url` -> a file path: "file:///abs/path", "package://pkg/rel"
/// (ros::package), or a plain path. Anything else is an error naming the
/// URL.
steadiface::Status ResolveCameraInfoUrl(const std::string& url,
                                        std::string* path);

/// Loads a calibration file as ROS camera drivers write it
/// (camera_calibration_parsers: the YAML of camera_calibration, or INI),
/// through ResolveCameraInfoUrl. Rejects a file without fx, fy or a size.
steadiface::Status LoadCameraInfoUrl(const std::string& url,
                                     sensor_msgs::CameraInfo* info);

/// Chooses the intrinsics of each image: a camera_info message when there
/// is one (it wins), else the `camera_info_url` file's, stamped and framed
/// like the image. Logs its choice once (and again whenever it changes),
/// through `log(is_error, text)`.
class CameraInfoSource {
 public:
  using Log = std::function<void(bool is_error, const std::string& text)>;
  explicit CameraInfoSource(Log log) : log_(std::move(log)) {}

  /// Loads the file; an empty URL means "no file" (Ok).
  steadiface::Status Load(const std::string& url);
  bool has_file_info() const { return has_file_; }
  const std::string& url() const { return url_; }

  /// The camera_info for `image`: `from_message` if set, else the file's.
  /// Null when there is neither, or when the file's size differs from the
  /// image's (reported as an error, throttled to once per change).
  sensor_msgs::CameraInfoConstPtr Select(
      const sensor_msgs::Image& image,
      const sensor_msgs::CameraInfoConstPtr& from_message);

 private:
  enum class Choice { kNone, kMessage, kFile, kSizeMismatch };
  void Report(Choice c, const sensor_msgs::Image& image);

  Log log_;
  std::string url_;
  bool has_file_ = false;
  sensor_msgs::CameraInfo file_info_;
  Choice last_ = Choice::kNone;
};

}  // namespace steadiface_ros
