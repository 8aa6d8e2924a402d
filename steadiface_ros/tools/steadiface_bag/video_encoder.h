#pragma once

#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace steadiface_bag {

/// A video file being encoded (MPEG-4 part 2 in an .mp4, through OpenCV's
/// videoio). The encoder lives in a module of its own,
/// libsteadiface_video_encoder.so, which the bag tool loads only for
/// --video: videoio links about 100 libraries (FFmpeg's, GStreamer's) that
/// every start of the tool would otherwise load and relocate (0.09 s of a
/// 1.9 s run on the speed protocol's clip, see docs/benchmarks.md).
class VideoEncoder {
 public:
  virtual ~VideoEncoder() = default;
  /// Appends one frame (bgr8, the size given at opening).
  virtual void Write(const cv::Mat& bgr) = 0;
  /// Finishes the file (also done on destruction).
  virtual void Close() = 0;
};

/// Loads the module (beside the tool's libraries: <exe dir>/../, else by
/// the library search path) and opens `path`. Null, with the reason in
/// *why, when the module cannot be loaded or the file not opened.
std::unique_ptr<VideoEncoder> OpenVideoEncoder(const std::string& path,
                                               double fps, cv::Size size,
                                               std::string* why);

}  // namespace steadiface_bag

/// The module's one entry point (C linkage, found with dlsym): a new encoder
/// writing `path`, or null if videoio cannot open it.
extern "C" steadiface_bag::VideoEncoder* steadiface_bag_open_video_encoder(
    const char* path, double fps, int width, int height);
