#pragma once

#include <opencv2/core.hpp>

namespace steadiface {

/// The grey version of an 8-bit image with 1, 3 (BGR) or 4 (BGRA)
/// channels: a 1-channel image is returned as is (shared, not copied),
/// others through cv::cvtColor. The face tracker, the gyro-vs-video check,
/// the calibrator and the pipeline all convert through here.
cv::Mat ToGrey(const cv::Mat& image);

}  // namespace steadiface
