#pragma once

#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/time.h"

namespace steadiface {
namespace testing_util {

inline std::string DataPath(const std::string& name) {
  return std::string(STEADIFACE_TEST_DATA_DIR) + "/" + name;
}

inline cv::Mat LoadImage(const std::string& name) {
  return cv::imread(DataPath(name), cv::IMREAD_COLOR);
}

inline Time At(double seconds) { return Time(FromSeconds(seconds)); }

/// The stabilizer tests' camera: 640x360, 1.2 rad horizontal field of view.
inline CameraModel Model640x360() {
  CameraModel m;
  EXPECT_TRUE(CameraModel::Create(IntrinsicsFromHorizontalFov(640, 360, 1.2),
                                  CameraModelOptions(), &m)
                  .ok());
  return m;
}

}  // namespace testing_util
}  // namespace steadiface
