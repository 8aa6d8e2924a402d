#pragma once

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include "steadiface/FaceLandmarks.h"
#include "steadiface_bag/bounded_queue.h"
#include "steadiface_bag/indexed_bag_reader.h"
#include "steadiface_core/common/status.h"

namespace steadiface_bag {

/// "/a/b" for "a/b" and "/a/b" (bags store topics with or without the
/// leading '/').
std::string NormalizeTopic(const std::string& topic);

/// The topics the tool reads. `landmarks` may be empty.
struct BagTopics {
  std::string image = "camera/image_raw";
  std::string info = "camera/camera_info";
  std::string imu = "imu";
  std::string landmarks;
};

/// One decoded bag message: exactly one pointer is set for the topics the
/// tool reads (none for a message whose type did not instantiate, or a
/// compressed image that did not decode).
struct BagItem {
  ros::Time time;
  sensor_msgs::ImuConstPtr imu;
  sensor_msgs::CameraInfoConstPtr info;
  sensor_msgs::ImageConstPtr image;
  steadiface::FaceLandmarksConstPtr landmarks;
};

/// The reader stage: opens the input bag, checks its topics and types, and
/// decodes the wanted messages in bag order on its own thread into a bounded
/// queue (LZ4/BZ2 decompression and deserialization overlap the
/// stabilizer). The messages come through IndexedBagReader when the bag is
/// one it reads (version 2.0, indexed, chunks uncompressed or LZ4: what
/// `rosbag record` writes), else through rosbag::View; the order is the
/// same either way.
class BagReader {
 public:
  /// `use_indexed_reader`: read through IndexedBagReader when the bag is
  /// one it handles (the same messages in the same order, less work),
  /// else through rosbag::View. `verify_checksums`: the indexed reader
  /// checks LZ4 checksums (rosbag::View always does).
  BagReader(const std::string& path, const BagTopics& topics, bool use_indexed_reader = true,
            bool verify_checksums = false)
      : path_(path),
        topics_(topics),
        use_indexed_reader_(use_indexed_reader),
        verify_checksums_(verify_checksums) {}
  ~BagReader();

  /// Opens the bag and checks the topics. A missing image topic, a wrong
  /// type, or a missing camera_info topic when `info_required` is an error;
  /// a missing IMU topic only a warning (frames pass through unstabilized).
  /// Messages go to stderr.
  steadiface::Status Open(bool info_required);
  /// Whether the bag has the camera_info topic.
  bool has_info() const { return has_info_; }
  /// The image topic holds sensor_msgs/CompressedImage (jpeg/png, decoded
  /// on the reader thread).
  bool compressed() const { return compressed_; }
  /// Compressed images that did not decode, and (indexed reader) messages
  /// that did not deserialize; each skipped (read after Join).
  size_t decode_failures() const { return decode_failures_; }
  /// Number of messages on the image topic, and on the IMU topic.
  size_t ImageCount() const;
  size_t ImuCount() const;
  /// Starts the reader thread; it closes `queue` at the end or on error.
  void Start(BoundedQueue<BagItem>* queue);
  /// Waits for the reader thread; returns its error ("" if none).
  std::string Join();
  void Close() {
    fast_.reset();
    if (bag_) bag_->close();
  }
  /// Whether the messages are read through IndexedBagReader (after Open).
  bool indexed() const { return fast_ != nullptr; }

 private:
  std::vector<std::string> WithAndWithoutSlash(const std::string& t) const;
  size_t Count(const std::string& topic) const;  // messages on `topic`
  // The reader thread's work: every message of the topics, in bag order,
  // through the indexed reader or rosbag::View.
  void ReadAll(BoundedQueue<BagItem>* queue);
  void ReadIndexed(const std::vector<std::string>& topics, BoundedQueue<BagItem>* queue);
  void ReadView(const std::vector<std::string>& topics, BoundedQueue<BagItem>* queue);
  // One message of `raw_topic` at `time` into the queue; `as(static_cast<M*>(nullptr))`
  // gives it as an M (null if it is not one). False when the queue is closed.
  template <typename As>
  bool Dispatch(const std::string& raw_topic, const ros::Time& time, As as,
                BoundedQueue<BagItem>* queue);

  const std::string path_;
  const BagTopics topics_;
  const bool use_indexed_reader_;
  const bool verify_checksums_;
  std::unique_ptr<rosbag::Bag> bag_;  // only when fast_ cannot read the bag
  std::unique_ptr<IndexedBagReader> fast_;
  bool has_info_ = false;
  bool compressed_ = false;
  size_t decode_failures_ = 0;  // written by the reader thread, read after join
  std::thread thread_;
  std::string error_;  // written by the reader thread, read after join
  // The topics' normalized names (NormalizeTopic), set by ReadAll.
  std::string imu_, info_, landmarks_, image_;
};

}  // namespace steadiface_bag
