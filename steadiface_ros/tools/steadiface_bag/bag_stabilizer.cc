#include "steadiface_bag/bag_stabilizer.h"

#include <cmath>

namespace steadiface_bag {

void BagStabilizer::Process(const BagItem& item) {
  if (item.imu) {
    wrapper_->OnImu(*item.imu);
  } else if (const auto& info = item.info) {
    in_info_ = *info;
    have_in_info_ = true;
    infos_[info->header.stamp] = info;
    while (infos_.size() > 64) infos_.erase(infos_.begin());
  } else if (item.landmarks) {
    wrapper_->OnLandmarks(*item.landmarks);
  } else if (const auto& img = item.image) {
    const double stamp = img->header.stamp.toSec();
    if (stamp < selection_.start_stamp - 1e-6) return;
    if (!selection_.only.empty() &&
        !selection_.only.count(std::llround(stamp * 1e3)))
      return;
    waiting_.push_back(img);
  }
  // Pair images with the camera_info of the same stamp (either order).
  while (!waiting_.empty()) {
    sensor_msgs::CameraInfoConstPtr info;
    if (use_file_info_) {
      // No camera_info in the bag: the camera_info_url's.
      info = info_source_->Select(*waiting_.front(), nullptr);
      if (info) {
        in_info_ = *info;
        have_in_info_ = true;
      } else {
        waiting_.pop_front();  // size mismatch: reported by the source
        continue;
      }
    } else {
      auto it = infos_.find(waiting_.front()->header.stamp);
      if (it == infos_.end()) {
        // No info for this image after 8 more: use the latest one.
        if (waiting_.size() > 8) {
          if (infos_.empty()) {
            waiting_.pop_front();
            continue;
          }
          it = std::prev(infos_.end());
        } else {
          break;
        }
      }
      info = info_source_->Select(*waiting_.front(), it->second);
    }
    const sensor_msgs::ImageConstPtr img = waiting_.front();
    waiting_.pop_front();
    if (on_image_) on_image_(*img);
    wrapper_->OnImage(img, info, item.time);
  }
  wrapper_->OnTimer(item.time);
}

}  // namespace steadiface_bag
