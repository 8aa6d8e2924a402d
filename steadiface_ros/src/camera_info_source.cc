#include "steadiface_ros/camera_info_source.h"

#include <fstream>

#include <camera_calibration_parsers/parse.h>

#include "steadiface_ros/resource_url.h"

namespace steadiface_ros {

using steadiface::Status;

Status ResolveCameraInfoUrl(const std::string& url, std::string* path) {
  return ResolveResourceUrl("camera_info_url", url, path);
}

Status LoadCameraInfoUrl(const std::string& url,
                         sensor_msgs::CameraInfo* info) {
  std::string path;
  Status s = ResolveCameraInfoUrl(url, &path);
  if (!s.ok()) return s;
  if (!std::ifstream(path).good()) {
    return Status::Error("camera_info_url '" + url + "': cannot read '" + path +
                         "'");
  }
  std::string camera_name;
  sensor_msgs::CameraInfo ci;
  if (!camera_calibration_parsers::readCalibration(path, camera_name, ci)) {
    return Status::Error(
        "camera_info_url '" + url + "': '" + path +
        "' is not a camera calibration file (YAML or INI as written by "
        "camera_calibration)");
  }
  if (ci.width == 0 || ci.height == 0 || ci.K[0] <= 0.0 || ci.K[4] <= 0.0) {
    return Status::Error(
        "camera_info_url '" + url +
        "': the file needs image_width, image_height and a camera_matrix "
        "with positive fx, fy");
  }
  *info = ci;
  return Status::Ok();
}

Status CameraInfoSource::Load(const std::string& url) {
  url_ = url;
  has_file_ = false;
  if (url.empty()) return Status::Ok();
  Status s = LoadCameraInfoUrl(url, &file_info_);
  has_file_ = s.ok();
  return s;
}

sensor_msgs::CameraInfoConstPtr CameraInfoSource::Select(
    const sensor_msgs::Image& image,
    const sensor_msgs::CameraInfoConstPtr& from_message) {
  if (from_message) {
    Report(Choice::kMessage, image);
    return from_message;
  }
  if (!has_file_) return nullptr;
  if (file_info_.width != image.width || file_info_.height != image.height) {
    Report(Choice::kSizeMismatch, image);
    return nullptr;
  }
  Report(Choice::kFile, image);
  sensor_msgs::CameraInfoPtr info(new sensor_msgs::CameraInfo(file_info_));
  info->header = image.header;
  return info;
}

void CameraInfoSource::Report(Choice c, const sensor_msgs::Image& image) {
  if (c == last_) return;
  last_ = c;
  if (!log_) return;
  switch (c) {
    case Choice::kMessage:
      log_(false,
           has_file_
               ? "intrinsics from the camera_info messages (they win over "
                 "camera_info_url " +
                     url_ + ")"
               : "intrinsics from the camera_info messages");
      break;
    case Choice::kFile:
      log_(false, "intrinsics from camera_info_url " + url_ +
                      " (no camera_info message)");
      break;
    case Choice::kSizeMismatch:
      log_(true, "camera_info_url " + url_ + " is for " +
                     std::to_string(file_info_.width) + "x" +
                     std::to_string(file_info_.height) +
                     " images, but the images are " +
                     std::to_string(image.width) + "x" +
                     std::to_string(image.height) + ": frames dropped");
      break;
    case Choice::kNone:
      break;
  }
}

}  // namespace steadiface_ros
