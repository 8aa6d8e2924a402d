// libFuzzer: image message validation and conversion (ROS adapter): random
// sizes, steps, encodings, endianness and data lengths. Whatever is
// accepted must be readable to its last byte (ASan checks) and match the
// message's size.
#include <cstdlib>

#include <sensor_msgs/image_encodings.h>

#include "fuzz_util.h"
#include "steadiface_ros/msg_conversion.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  static const char* kEncodings[] = {"mono8", "bgr8", "rgb8", "bgra8", "rgba8", "mono16",
                                     "bgr16", "8UC1", "8UC3", "8UC4", "32FC1", "yuv422",
                                     "bayer_rggb8", "16UC1", "", "nonsense"};
  sensor_msgs::Image m;
  m.width = in.Get<uint16_t>() % 300;
  m.height = in.Get<uint16_t>() % 300;
  m.encoding = kEncodings[in.Byte() % 16];
  m.is_bigendian = in.Byte() % 2;
  const int step_mode = in.Byte() % 4;
  m.step = step_mode == 0 ? in.Get<uint16_t>() : m.width * (1 + step_mode);
  size_t n = in.Byte() % 3 == 0 ? in.Get<uint32_t>() % 400000 : static_cast<size_t>(m.step) * m.height;
  n = std::min<size_t>(n, 2000000);
  m.data.resize(n);
  for (size_t i = 0; i < n && !in.done(); ++i) m.data[i] = in.Byte();
  cv::Mat img;
  if (steadiface_ros::ToCvImage(m, &img).ok()) {
    if (img.cols != static_cast<int>(m.width) || img.rows != static_cast<int>(m.height)) abort();
    if (img.depth() != CV_8U) abort();
    volatile unsigned sum = 0;
    for (int y = 0; y < img.rows; ++y) {
      const uint8_t* row = img.ptr<uint8_t>(y);
      for (size_t x = 0; x < img.cols * img.elemSize(); ++x) sum += row[x];
    }
  }
  return 0;
}
