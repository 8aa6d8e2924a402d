// libsteadiface_image_decoder.so: cv::imdecode for FromCompressedImage, in
// a module so that only a process that meets a compressed image loads
// OpenCV's imgcodecs (see image_decoder.h).
#include <cstddef>
#include <cstdint>

#include <opencv2/imgcodecs.hpp>

// 1 with the decoded image in *out; 0 (and *out empty) when the payload
// does not decode. No exception leaves the module.
extern "C" int steadiface_ros_decode_image(const uint8_t* data, size_t size,
                                           cv::Mat* out) {
  try {
    *out = cv::imdecode(
        cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<uint8_t*>(data)),
        cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    out->release();
  } catch (const std::exception&) {
    out->release();
  }
  return out->empty() ? 0 : 1;
}
