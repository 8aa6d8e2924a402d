#pragma once

#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "steadiface_core/time.h"

namespace steadiface {
namespace testing_util {

inline std::string DataPath(const std::string& name) {
  return std::string(STEADIFACE_TEST_DATA_DIR) + "/" + name;
}

inline cv::Mat LoadImage(const std::string& name) {
  return cv::imread(DataPath(name), cv::IMREAD_COLOR);
}

inline Time At(double seconds) { return Time(FromSeconds(seconds)); }

}  // namespace testing_util
}  // namespace steadiface
