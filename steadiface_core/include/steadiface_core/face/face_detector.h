#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "steadiface_core/common/status.h"
#include "steadiface_core/face/face_types.h"

namespace steadiface {

/// Which detector to use.
enum class FaceDetectorType {
  kDlibHog,        ///< dlib's HOG frontal face detector (no model file)
  kOpenCvCascade,  ///< OpenCV Haar/LBP cascade (Debian opencv-data)
};

struct FaceDetectorOptions {
  FaceDetectorType type = FaceDetectorType::kDlibHog;
  /// Detection runs on a copy downscaled so its longest side is at most this
  /// [px]. Faces smaller than ~80 px in that copy (dlib) are missed.
  int max_side_px = 640;
  /// Cascade file for kOpenCvCascade.
  std::string cascade_path =
      "/usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml";
  /// dlib HOG score threshold (higher = fewer false positives) [-]. At 0 the
  /// portrait test image gives large false positives scoring 0.03-0.23.
  double dlib_threshold = 0.3;
  /// Minimum face size in full-resolution pixels [px].
  int min_face_px = 40;
};

Status ValidateFaceDetectorOptions(const FaceDetectorOptions& options);

/// One small interface over both detectors (paper §3.1: "several popular
/// ones work equally well").
class FaceDetector {
 public:
  virtual ~FaceDetector() = default;
  /// Detects faces in `roi` of the 8-bit grayscale `gray`; boxes are in
  /// full-image pixels, largest first. `max_side_px` > 0 overrides the
  /// downscale limit (re-detection around a known face uses a small copy).
  virtual Status Detect(const cv::Mat& gray, const cv::Rect& roi,
                        std::vector<FaceBox>* faces, int max_side_px = 0) = 0;

  static Status Create(const FaceDetectorOptions& options,
                       std::unique_ptr<FaceDetector>* out);
};

}  // namespace steadiface
