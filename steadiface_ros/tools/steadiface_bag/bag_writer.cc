#include "steadiface_bag/bag_writer.h"

#include <cstdio>
#include <iostream>

#include <tf2_msgs/TFMessage.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_ros/msg_conversion.h"

namespace steadiface_bag {

AsyncBagWriter::AsyncBagWriter(rosbag::Bag* bag) : bag_(bag), queue_(64) {
  thread_ = std::thread([this] {
    std::function<void()> job;
    while (queue_.Pop(&job)) {
      if (!error_.empty()) continue;  // drain after a failure
      try {
        job();
      } catch (const std::exception& e) {
        error_ = e.what();
      }
    }
  });
}

std::string AsyncBagWriter::Finish() {
  if (thread_.joinable()) {
    queue_.Close();
    thread_.join();
  }
  return error_;
}

void BagSink::PublishImage(const sensor_msgs::ImagePtr& image,
                           const sensor_msgs::CameraInfoPtr& info) {
  last_image = image;
  last_info = *info;
  if (out) {
    out->Write(T("image_stabilized/image_raw"), image->header.stamp,
               sensor_msgs::ImageConstPtr(image));
    out->Write(T("image_stabilized/camera_info"), info->header.stamp,
               sensor_msgs::CameraInfoConstPtr(info));
  }
}

void BagSink::PublishOutputInfo(const sensor_msgs::CameraInfoPtr& info) {
  last_info = *info;
}

void BagSink::PublishLandmarks(const steadiface::FaceLandmarks& m) {
  landmarks.push_back(m);
  if (out) out->WriteCopy(T("face_landmarks"), m.header.stamp, m);
}

void BagSink::PublishState(const steadiface::StabilizerState& m) {
  states.push_back(m);
  infos_out.push_back(last_info);  // PublishImage precedes PublishState
  if (out) out->WriteCopy(T("state"), m.header.stamp, m);
}

void BagSink::PublishTf(
    const std::vector<geometry_msgs::TransformStamped>& tf) {
  tfs.insert(tfs.end(), tf.begin(), tf.end());
  if (out && !tf.empty()) {
    tf2_msgs::TFMessage m;
    m.transforms = tf;
    out->WriteCopy("/tf", tf.front().header.stamp, m);
  }
}

void BagSink::PublishDebugImage(const sensor_msgs::ImagePtr& image) {
  last_debug = image;
  if (out && debug_to_bag) {
    out->Write(T("debug_image"), image->header.stamp,
               sensor_msgs::ImageConstPtr(image));
  }
}

void BagSink::Warn(const std::string& key, const std::string& text) {
  if (warnings[key]++ == 0) std::cerr << "warning: " << text << "\n";
}

void BagSink::Error(const std::string& key, const std::string& text) {
  if (warnings[key]++ == 0) std::cerr << "error: " << text << "\n";
}

SideBySideVideo::SideBySideVideo(const std::string& path)
    : path_(path), tmp_(path.empty() ? "" : path + ".part.mp4") {}

SideBySideVideo::~SideBySideVideo() {
  if (thread_.joinable()) {
    queue_->Close();
    thread_.join();
  }
}

namespace {

// An image message as a BGR copy (grey and BGRA converted), for the side
// by side video; empty if it does not convert.
cv::Mat ToBgr(const sensor_msgs::Image& image) {
  cv::Mat mat, bgr;
  if (!steadiface_ros::ToCvImage(image, &mat).ok()) return bgr;
  if (mat.channels() == 1) {
    cv::cvtColor(mat, bgr, cv::COLOR_GRAY2BGR);
  } else if (mat.channels() == 4) {
    cv::cvtColor(mat, bgr, cv::COLOR_BGRA2BGR);
  } else {
    bgr = mat.clone();
  }
  return bgr;
}

}  // namespace

void SideBySideVideo::AddInput(const sensor_msgs::Image& image) {
  if (!enabled()) return;
  cv::Mat bgr = ToBgr(image);
  if (!bgr.empty()) inputs_[image.header.stamp] = bgr;
  while (inputs_.size() > 32) inputs_.erase(inputs_.begin());
}

void SideBySideVideo::AddOutput(BagSink* sink) {
  // Pair every new stabilized output with its input frame.
  if (!enabled() || !sink->last_image) return;
  const ros::Time t = sink->last_image->header.stamp;
  auto it = inputs_.find(t);
  if (it == inputs_.end()) return;
  cv::Mat left = it->second, right;
  if (sink->debug && sink->last_debug && sink->last_debug->header.stamp == t) {
    left = ToBgr(*sink->last_debug);
  }
  right = ToBgr(*sink->last_image);
  if (left.empty() || right.empty()) return;
  cv::resize(right, right, left.size());
  cv::Mat both;
  cv::hconcat(left, right, both);
  if (!queue_) {  // first frame: open (the encoder thread owns video_ after)
    const double fps = 30.0;
    std::string why;
    video_ = OpenVideoEncoder(tmp_, fps, both.size(), &why);
    if (!video_) {
      std::cerr << "steadiface_bag: " << why << "\n";
      path_.clear();
      failed_ = true;
      return;
    }
    queue_.reset(new BoundedQueue<cv::Mat>(8));
    thread_ = std::thread([this] {
      cv::Mat frame;
      while (queue_->Pop(&frame)) video_->Write(frame);
    });
  }
  queue_->Push(both);
  inputs_.erase(inputs_.begin(), std::next(it));
  sink->last_image.reset();
}

void SideBySideVideo::Finish() {
  if (thread_.joinable()) {
    queue_->Close();
    thread_.join();
  }
  if (video_) {
    video_->Close();
    video_.reset();
    std::rename(tmp_.c_str(), path_.c_str());
  }
}

}  // namespace steadiface_bag
