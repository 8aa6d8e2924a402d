// libsteadiface_video_encoder.so: the bag tool's --video encoder, in a module
// so that only runs that write a video load OpenCV's videoio.
#include <opencv2/videoio.hpp>

#include "steadiface_bag/video_encoder.h"

namespace steadiface_bag {
namespace {

class OpenCvVideoEncoder : public VideoEncoder {
 public:
  bool Open(const char* path, double fps, int width, int height) {
    return writer_.open(path, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps,
                        cv::Size(width, height));
  }
  ~OpenCvVideoEncoder() override { Close(); }
  void Write(const cv::Mat& bgr) override { writer_.write(bgr); }
  void Close() override {
    if (writer_.isOpened()) writer_.release();
  }

 private:
  cv::VideoWriter writer_;
};

}  // namespace
}  // namespace steadiface_bag

extern "C" steadiface_bag::VideoEncoder* steadiface_bag_open_video_encoder(
    const char* path, double fps, int width, int height) {
  auto* e = new steadiface_bag::OpenCvVideoEncoder;
  if (!e->Open(path, fps, width, height)) {
    delete e;
    return nullptr;
  }
  return e;
}
