#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <rosbag/bag.h>
#include <opencv2/core.hpp>

#include "steadiface_bag/bounded_queue.h"
#include "steadiface_bag/video_encoder.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace steadiface_bag {

/// The writer stage: bag writes on their own thread, through a bounded
/// queue. The first write error is kept and reported at the end (the output
/// is then not renamed into place).
class AsyncBagWriter {
 public:
  explicit AsyncBagWriter(rosbag::Bag* bag);
  ~AsyncBagWriter() { Finish(); }
  template <typename M>
  void Write(const std::string& topic, const ros::Time& t,
             const boost::shared_ptr<const M>& m) {
    rosbag::Bag* bag = bag_;
    queue_.Push([bag, topic, t, m] { bag->write(topic, t, *m); });
  }
  template <typename M>
  void WriteCopy(const std::string& topic, const ros::Time& t, const M& m) {
    Write(topic, t, boost::shared_ptr<const M>(new M(m)));
  }
  /// Waits for every queued write; returns the first error ("" if none).
  std::string Finish();

 private:
  rosbag::Bag* bag_;
  BoundedQueue<std::function<void()>> queue_;
  std::thread thread_;
  std::string error_;  // written by the writer thread only, read after join
};

/// Collects everything the wrapper produces: to the output bag (when one is
/// written), and in memory for the report and the video.
class BagSink : public steadiface_ros::OutputSink {
 public:
  AsyncBagWriter* out = nullptr;
  /// Render debug images (for the side-by-side video).
  bool debug = false;
  /// Also write the rendered debug images into the output bag (they are raw
  /// images: about as large as the stabilized stream itself).
  bool debug_to_bag = false;
  /// The stabilized pixels are needed (an output bag or the side-by-side
  /// video); with only a report, just the output camera_info is kept.
  bool wants_image = true;
  /// Same names as the node publishes in the camera's namespace.
  std::string ns = "/camera";
  std::string T(const std::string& leaf) const { return ns + "/" + leaf; }
  sensor_msgs::ImagePtr last_image, last_debug;
  sensor_msgs::CameraInfo last_info;
  std::vector<steadiface::StabilizerState> states;
  std::vector<sensor_msgs::CameraInfo> infos_out;  // parallel to states
  std::vector<steadiface::FaceLandmarks> landmarks;
  std::vector<geometry_msgs::TransformStamped> tfs;
  std::map<std::string, int> warnings;
  /// Called with every stabilized frame (ground-truth scoring); optional.
  std::function<void(const steadiface::PipelineFrame&, const steadiface::Pipeline&)> on_frame;

  void PublishImage(const sensor_msgs::ImagePtr& image,
                    const sensor_msgs::CameraInfoPtr& info) override;
  void PublishLandmarks(const steadiface::FaceLandmarks& m) override;
  void PublishState(const steadiface::StabilizerState& m) override;
  void PublishTf(
      const std::vector<geometry_msgs::TransformStamped>& tf) override;
  bool WantsDebugImage() const override { return debug; }
  bool WantsImage() const override { return wants_image; }
  void PublishOutputInfo(const sensor_msgs::CameraInfoPtr& info) override;
  void PublishDebugImage(const sensor_msgs::ImagePtr& image) override;
  void Warn(const std::string& key, const std::string& text) override;
  void Error(const std::string& key, const std::string& text) override;
  void OnFrameProcessed(const steadiface::PipelineFrame& frame,
                        const steadiface::Pipeline& pipeline) override {
    if (on_frame) on_frame(frame, pipeline);
  }
};

/// The side-by-side MP4 (input, or its debug overlay | stabilized), encoded
/// on its own thread. Keeps a bounded set of input frames to pair with the
/// outputs; written to PATH.part.mp4 and renamed into place by Finish.
class SideBySideVideo {
 public:
  explicit SideBySideVideo(const std::string& path);
  ~SideBySideVideo();
  bool enabled() const { return !path_.empty(); }
  /// A video was asked for and could not be written.
  bool failed() const { return failed_; }
  /// An input frame as it enters the stabilizer.
  void AddInput(const sensor_msgs::Image& image);
  /// Pairs the sink's newest stabilized output (if any) with its input.
  void AddOutput(BagSink* sink);
  /// Flushes the encoder and renames the file into place.
  void Finish();

 private:
  std::string path_, tmp_;
  bool failed_ = false;
  std::map<ros::Time, cv::Mat> inputs_;  // bounded
  std::unique_ptr<VideoEncoder> video_;
  std::unique_ptr<BoundedQueue<cv::Mat>> queue_;
  std::thread thread_;  // owns video_ once started
};

}  // namespace steadiface_bag
