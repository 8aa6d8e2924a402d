// StabilizerWrapper under bad input: bad images, camera_info missing or
// changing, bursts beyond the queue.
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "wrapper_test_util.h"

namespace steadiface_ros {
namespace wrapper_test {
namespace {

TEST(WrapperTest, BadImagesAreDroppedWithAReason) {
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  const Stream& st = TestStream();
  Feed(&w, st, 0, -1, {}, [&](int i) -> sensor_msgs::ImagePtr {
    sensor_msgs::ImagePtr m = Copy(st.images[i]);
    switch (i) {
      case 5:
        m->encoding = "no_such_encoding";
        break;
      case 6:
        m->width = m->height = 0;
        m->data.clear();
        break;
      case 7:
        m->data.resize(m->data.size() / 2);
        break;  // step * height != size
      case 8:
        m->step = 10;
        break;  // step < width * 3
      case 9:
        m->width = 100;
        m->step = 300;
        m->data.resize(300 * m->height);
        break;  // != camera_info
      case 10:
        m->encoding = "mono16";
        m->step = m->width * 2;
        m->data.assign(m->step * m->height, 0x40);
        break;  // converted by cv_bridge
      case 11:
        m->encoding = "32FC1";
        m->step = m->width * 4;
        m->data.assign(m->step * m->height, 0);
        break;  // not cleanly: refused
      default:
        break;
    }
    return m;
  });
  const WrapperStatus s = w.CurrentStatus();
  EXPECT_EQ(s.counters.dropped_bad_image, 6u);  // 5, 6, 7, 8, 9, 11
  EXPECT_EQ(sink.states.size(), st.images.size() - 6);
  EXPECT_GT(sink.errors["image"], 0);
  EXPECT_GT(sink.errors["image_size"], 0);
  ExpectAllFinite(sink);
}

TEST(WrapperTest, CameraInfoMissingOrChangingIsHandled) {
  Sink sink;
  StabilizerWrapper w(Options(), WrapperOptions(), &sink);
  const Stream& st = TestStream();
  size_t g = 0;
  sensor_msgs::CameraInfoPtr uncal(new sensor_msgs::CameraInfo(*st.info));
  uncal->K.fill(0.0);
  for (size_t i = 0; i < st.images.size(); ++i) {
    while (g < st.imu.size() &&
           st.imu[g].header.stamp <=
               st.images[i]->header.stamp + ros::Duration(0.03)) {
      w.OnImu(st.imu[g++]);
    }
    if (i == 3) {
      w.OnImage(st.images[i], nullptr,
                st.images[i]->header.stamp);  // no camera_info
    } else if (i == 4) {
      w.OnImage(st.images[i], uncal,
                st.images[i]->header.stamp);  // uncalibrated
    } else if (i >= 30) {
      // Resolution change mid-stream: half-size frames with matching info.
      sensor_msgs::CameraInfoPtr half(new sensor_msgs::CameraInfo(*st.info));
      half->width /= 2;
      half->height /= 2;
      for (int k : {0, 2, 4, 5}) half->K[k] /= 2;
      cv::Mat small;
      cv::resize(cv_bridge::toCvShare(st.images[i])->image, small,
                 cv::Size(half->width, half->height));
      sensor_msgs::ImagePtr m =
          cv_bridge::CvImage(st.images[i]->header, "bgr8", small).toImageMsg();
      w.OnImage(m, half, m->header.stamp);
    } else {
      w.OnImage(st.images[i], st.info, st.images[i]->header.stamp);
    }
    w.OnTimer(st.images[i]->header.stamp);
  }
  w.Flush();
  const WrapperStatus s = w.CurrentStatus();
  EXPECT_EQ(s.counters.dropped_bad_info, 2u);
  EXPECT_EQ(s.counters.rebuilds, 1u);
  EXPECT_EQ(sink.images.back()->width, st.info->width / 2);
  EXPECT_EQ(sink.infos.back()->width, st.info->width / 2);
  EXPECT_EQ(sink.states.size(), st.images.size() - 2);
  ExpectAllFinite(sink);
}

TEST(WrapperTest, BurstsBeyondTheQueueAreBoundedAndCounted) {
  Sink sink;
  WrapperOptions wo;
  wo.scheduler.frame_queue_size = 5;
  StabilizerWrapper w(Options(), wo, &sink);
  const Stream& st = TestStream();
  // A burst of 30 frames before any IMU arrives, and no time passing.
  for (int i = 0; i < 30; ++i) w.OnImage(st.images[i], st.info, ros::Time(1.0));
  EXPECT_EQ(w.CurrentStatus().counters.dropped_queue_full, 25u);
  for (const auto& m : st.imu) w.OnImu(m);
  w.Flush();
  EXPECT_EQ(sink.states.size(), 5u);
}

}  // namespace
}  // namespace wrapper_test
}  // namespace steadiface_ros
