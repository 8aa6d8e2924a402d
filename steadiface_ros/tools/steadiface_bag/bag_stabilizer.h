#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <set>

#include "steadiface_bag/bag_reader.h"
#include "steadiface_ros/camera_info_source.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace steadiface_bag {

/// Which images of the bag to process.
struct FrameSelection {
  double start_stamp = 0.0;  ///< images stamped before this [s] are skipped
  std::set<int64_t> only;    ///< if not empty: only these stamps [ms]
};

/// The stabilizer stage: feeds the decoded messages, in bag order, to the
/// StabilizerWrapper exactly as the nodelet's callbacks would. Pairs each
/// image with the camera_info of the same stamp (either order, or the latest
/// one after 8 images without a match) or, when the bag has none, with the
/// intrinsics of `camera_info_url`.
class BagStabilizer {
 public:
  BagStabilizer(steadiface_ros::StabilizerWrapper* wrapper,
                steadiface_ros::CameraInfoSource* info_source,
                bool bag_has_info, const FrameSelection& selection)
      : wrapper_(wrapper),
        info_source_(info_source),
        use_file_info_(!bag_has_info && info_source->has_file_info()),
        selection_(selection) {}

  /// Called with each image just before the wrapper gets it.
  void set_on_image(std::function<void(const sensor_msgs::Image&)> f) {
    on_image_ = std::move(f);
  }

  void Process(const BagItem& item);

  /// The camera_info of the input (the last one used), if any.
  bool have_input_info() const { return have_in_info_; }
  const sensor_msgs::CameraInfo& input_info() const { return in_info_; }

 private:
  steadiface_ros::StabilizerWrapper* wrapper_;
  steadiface_ros::CameraInfoSource* info_source_;
  const bool use_file_info_;  // the bag has no camera_info topic
  const FrameSelection selection_;
  std::function<void(const sensor_msgs::Image&)> on_image_;
  std::map<ros::Time, sensor_msgs::CameraInfoConstPtr> infos_;  // bounded
  std::deque<sensor_msgs::ImageConstPtr>
      waiting_;  // images whose info has not arrived
  sensor_msgs::CameraInfo in_info_;
  bool have_in_info_ = false;
};

}  // namespace steadiface_bag
