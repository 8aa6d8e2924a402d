// The image formats real cameras send, each converted against a ground
// truth built independently of the converter: a smooth colour picture,
// encoded by hand into each format (UYVY / YUYV with BT.601, bayer mosaics
// by sampling the right channel at each site, 16-bit by scaling), then
// decoded by ToCvImage / FromCompressedImage and compared.
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "steadiface_ros/msg_conversion.h"

namespace steadiface_ros {
namespace {

namespace enc = sensor_msgs::image_encodings;

// A smooth colour picture (demosaicing and chroma subsampling are exact
// only where colour varies slowly).
cv::Mat Picture(int w = 64, int h = 48) {
  cv::Mat bgr(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(40 + 2 * x),
                                          static_cast<uint8_t>(60 + 3 * y),
                                          static_cast<uint8_t>(200 - x - y));
    }
  }
  return bgr;
}

sensor_msgs::Image Message(const std::string& encoding, int w, int h,
                           int bytes_per_px) {
  sensor_msgs::Image m;
  m.encoding = encoding;
  m.width = w;
  m.height = h;
  m.step = w * bytes_per_px;
  m.data.assign(static_cast<size_t>(m.step) * h, 0);
  return m;
}

// Largest absolute difference over the interior (border pixels of a
// demosaic are extrapolated).
double MaxDiff(const cv::Mat& a, const cv::Mat& b, int border = 2) {
  const cv::Rect r(border, border, a.cols - 2 * border, a.rows - 2 * border);
  cv::Mat d;
  cv::absdiff(a(r), b(r), d);
  double mx = 0;
  cv::minMaxLoc(d.reshape(1), nullptr, &mx);
  return mx;
}

// BT.601 full-range-ish as OpenCV's YUV2BGR expects (video range).
void ToYuv(const cv::Vec3b& p, double* y, double* u, double* v) {
  const double b = p[0], g = p[1], r = p[2];
  *y = 16 + 0.257 * r + 0.504 * g + 0.098 * b;
  *u = 128 - 0.148 * r - 0.291 * g + 0.439 * b;
  *v = 128 + 0.439 * r - 0.368 * g - 0.071 * b;
}

sensor_msgs::Image Yuv422(const cv::Mat& bgr, bool uyvy,
                          const std::string& encoding) {
  sensor_msgs::Image m = Message(encoding, bgr.cols, bgr.rows, 2);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; x += 2) {
      double y0, u0, v0, y1, u1, v1;
      ToYuv(bgr.at<cv::Vec3b>(y, x), &y0, &u0, &v0);
      ToYuv(bgr.at<cv::Vec3b>(y, x + 1), &y1, &u1, &v1);
      uint8_t* q = &m.data[y * m.step + 2 * x];
      auto c = [](double v) {
        return cv::saturate_cast<uint8_t>(std::lround(v));
      };
      if (uyvy) {
        q[0] = c((u0 + u1) / 2), q[1] = c(y0), q[2] = c((v0 + v1) / 2),
        q[3] = c(y1);
      } else {
        q[0] = c(y0), q[1] = c((u0 + u1) / 2), q[2] = c(y1),
        q[3] = c((v0 + v1) / 2);
      }
    }
  }
  return m;
}

TEST(ImageFormatsTest, Yuv422UyvyAndYuyvFromUsbCamerasBecomeBgr) {
  const cv::Mat truth = Picture();
  for (const auto& [encoding, uyvy] : std::vector<std::pair<std::string, bool>>{
           {enc::YUV422, true}, {"yuyv", false}, {"yuv422_yuy2", false}}) {
    cv::Mat out;
    const steadiface::Status s = ToCvImage(Yuv422(truth, uyvy, encoding), &out);
    ASSERT_TRUE(s.ok()) << encoding << ": " << s.message();
    ASSERT_EQ(out.type(), CV_8UC3) << encoding;
    // Rounding plus shared chroma: a few grey levels on a smooth picture.
    EXPECT_LE(MaxDiff(out, truth, 0), 6.0) << encoding;
  }
  // A UYVY image read as YUYV would swap luma and chroma: far off.
  cv::Mat wrong;
  sensor_msgs::Image swapped = Yuv422(truth, true, "yuyv");
  ASSERT_TRUE(ToCvImage(swapped, &wrong).ok());
  EXPECT_GT(MaxDiff(wrong, truth, 0), 40.0);
  // An odd width cannot hold 4:2:2 pairs.
  sensor_msgs::Image odd = Message(enc::YUV422, 63, 4, 2);
  cv::Mat o;
  EXPECT_FALSE(ToCvImage(odd, &o).ok());
}

TEST(ImageFormatsTest, EveryBayerPatternDemosaicsToTheRightColours) {
  const cv::Mat truth = Picture();
  // The channel (b=0, g=1, r=2) at each site of the top-left 2x2.
  const std::vector<std::pair<std::string, std::array<int, 4>>> patterns = {
      {"rggb", {2, 1, 1, 0}},
      {"bggr", {0, 1, 1, 2}},
      {"gbrg", {1, 0, 2, 1}},
      {"grbg", {1, 2, 0, 1}}};
  for (const auto& [name, sites] : patterns) {
    for (int depth : {8, 16}) {
      const std::string encoding = "bayer_" + name + std::to_string(depth);
      sensor_msgs::Image m =
          Message(encoding, truth.cols, truth.rows, depth / 8);
      for (int y = 0; y < truth.rows; ++y) {
        for (int x = 0; x < truth.cols; ++x) {
          const int ch = sites[(y % 2) * 2 + (x % 2)];
          const uint8_t v = truth.at<cv::Vec3b>(y, x)[ch];
          if (depth == 8) {
            m.data[y * m.step + x] = v;
          } else {
            const uint16_t v16 =
                static_cast<uint16_t>(v * 257);  // full 16-bit range
            std::memcpy(&m.data[y * m.step + 2 * x], &v16, 2);
          }
        }
      }
      cv::Mat out;
      const steadiface::Status s = ToCvImage(m, &out);
      ASSERT_TRUE(s.ok()) << encoding << ": " << s.message();
      ASSERT_EQ(out.type(), CV_8UC3) << encoding;
      EXPECT_LE(MaxDiff(out, truth), 4.0) << encoding;
    }
  }
}

TEST(ImageFormatsTest, Mono16IsScaledFromItsFullRange) {
  const cv::Mat grey = [] {
    cv::Mat g;
    cv::cvtColor(Picture(), g, cv::COLOR_BGR2GRAY);
    return g;
  }();
  sensor_msgs::Image m = Message(enc::MONO16, grey.cols, grey.rows, 2);
  for (int y = 0; y < grey.rows; ++y) {
    for (int x = 0; x < grey.cols; ++x) {
      const uint16_t v = static_cast<uint16_t>(grey.at<uint8_t>(y, x) * 257);
      std::memcpy(&m.data[y * m.step + 2 * x], &v, 2);
    }
  }
  cv::Mat out;
  ASSERT_TRUE(ToCvImage(m, &out).ok());
  ASSERT_EQ(out.type(), CV_8UC1);
  EXPECT_LE(MaxDiff(out, grey, 0), 1.0);
  // Big-endian 16-bit data is refused with a message, not misread.
  m.is_bigendian = 1;
  const steadiface::Status s = ToCvImage(m, &out);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("big-endian"), std::string::npos) << s.message();
}

TEST(ImageFormatsTest, DepthAndUnknownImagesAreRefusedNamingTheEncoding) {
  cv::Mat out;
  for (const std::string e :
       {"32FC1", "16SC1", "no_such_encoding", "8UC2", "16UC2"}) {
    const int bpp = e == "32FC1" || e == "16UC2" ? 4 : 2;
    const steadiface::Status s = ToCvImage(Message(e, 8, 8, bpp), &out);
    EXPECT_FALSE(s.ok()) << e;
    EXPECT_NE(s.message().find(e), std::string::npos) << s.message();
  }
}

sensor_msgs::CompressedImage Compressed(const cv::Mat& img,
                                        const std::string& ext,
                                        const std::string& format) {
  sensor_msgs::CompressedImage c;
  c.header.stamp.fromSec(12.5);
  c.header.frame_id = "cam";
  c.format = format;
  std::vector<uint8_t> buf;
  EXPECT_TRUE(cv::imencode(ext, img, buf));
  c.data = buf;
  return c;
}

TEST(ImageFormatsTest, CompressedJpegAndPngAsImageTransportPublishesThem) {
  const cv::Mat truth = Picture();
  cv::Mat grey;
  cv::cvtColor(truth, grey, cv::COLOR_BGR2GRAY);
  struct Case {
    cv::Mat img;
    std::string ext, format, encoding;
    double tol;
  };
  for (const Case& c : std::vector<Case>{
           {truth, ".png", "bgr8; png compressed bgr8", enc::BGR8, 0},
           {truth, ".jpg", "bgr8; jpeg compressed bgr8", enc::BGR8, 12},
           {grey, ".png", "mono8; png compressed mono8", enc::MONO8, 0},
           {grey, ".jpg", "jpeg", enc::MONO8, 8}}) {
    sensor_msgs::ImagePtr msg;
    const steadiface::Status s =
        FromCompressedImage(Compressed(c.img, c.ext, c.format), &msg);
    ASSERT_TRUE(s.ok()) << c.format << ": " << s.message();
    EXPECT_EQ(msg->encoding, c.encoding) << c.format;
    EXPECT_EQ(msg->header.frame_id, "cam");
    EXPECT_DOUBLE_EQ(msg->header.stamp.toSec(), 12.5);
    cv::Mat out;
    ASSERT_TRUE(ToCvImage(*msg, &out).ok());
    EXPECT_LE(MaxDiff(out, c.img, 0), c.tol) << c.format;
  }
  sensor_msgs::ImagePtr msg;
  sensor_msgs::CompressedImage broken = Compressed(truth, ".jpg", "jpeg");
  broken.data.resize(20);
  steadiface::Status s = FromCompressedImage(broken, &msg);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("cannot decode"), std::string::npos)
      << s.message();
  s = FromCompressedImage(
      Compressed(truth, ".png", "16UC1; compressedDepth png"), &msg);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("depth"), std::string::npos) << s.message();
  broken.data.clear();
  EXPECT_FALSE(FromCompressedImage(broken, &msg).ok());
}

// ToImageMsg (which the stabilized and the debug images go out through)
// gives the very message cv_bridge's CvImage::toImageMsg gives, for
// continuous images and for a non-continuous view (rows copied tightly).
TEST(ImageFormatsTest, ToImageMsgIsWhatCvBridgeGives) {
  std_msgs::Header h;
  h.stamp.fromSec(3.25);
  h.frame_id = "cam_stabilized";
  h.seq = 7;
  const cv::Mat bgr = Picture(37, 23);
  cv::Mat grey, bgra, grey16;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
  grey.convertTo(grey16, CV_16U, 257.0);
  const cv::Mat view = bgr(cv::Rect(3, 2, 30, 17));  // not continuous
  ASSERT_FALSE(view.isContinuous());
  struct Case {
    cv::Mat img;
    std::string encoding;
  };
  for (const Case& c : std::vector<Case>{{bgr, enc::BGR8},
                                         {grey, enc::MONO8},
                                         {bgra, enc::BGRA8},
                                         {grey16, enc::MONO16},
                                         {view, enc::BGR8},
                                         {cv::Mat(), enc::BGR8}}) {
    const sensor_msgs::ImagePtr ours = ToImageMsg(h, c.encoding, c.img);
    const sensor_msgs::ImagePtr theirs =
        cv_bridge::CvImage(h, c.encoding, c.img).toImageMsg();
    EXPECT_EQ(ours->header.stamp, theirs->header.stamp);
    EXPECT_EQ(ours->header.frame_id, theirs->header.frame_id);
    EXPECT_EQ(ours->header.seq, theirs->header.seq);
    EXPECT_EQ(ours->height, theirs->height) << c.encoding;
    EXPECT_EQ(ours->width, theirs->width) << c.encoding;
    EXPECT_EQ(ours->encoding, theirs->encoding);
    EXPECT_EQ(ours->is_bigendian, theirs->is_bigendian);
    EXPECT_EQ(ours->step, theirs->step) << c.encoding;
    EXPECT_TRUE(ours->data == theirs->data) << c.encoding;
    if (!c.img.empty()) {
      cv::Mat back;
      ASSERT_TRUE(ToCvImage(*ours, &back).ok());
      if (c.img.depth() == CV_8U && c.img.channels() != 4) {
        EXPECT_EQ(MaxDiff(back, c.img, 0), 0) << c.encoding;
      }
    }
  }
}

}  // namespace
}  // namespace steadiface_ros
