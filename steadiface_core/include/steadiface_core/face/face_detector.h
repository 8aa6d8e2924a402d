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
  /// Smallest face to find, in full-resolution pixels [px]. The search
  /// looks for faces this small in upsampled tiles (face/search_schedule.h);
  /// detections narrower than 0.8 x this are dropped (a box measures a face
  /// to about 10 %).
  int min_face_px = 30;
};

Status ValidateFaceDetectorOptions(const FaceDetectorOptions& options);

/// One small interface over both detectors (paper §3.1: "several popular
/// ones work equally well").
class FaceDetector {
 public:
  virtual ~FaceDetector() = default;
  /// Detects faces in `roi` of the 8-bit grayscale `gray`; boxes are in
  /// full-image pixels, largest first. `scale` > 0 sets the scale of the
  /// copy the detector sees, below 1 to shrink it, above 1 to find faces
  /// smaller than the detector's window; 0 shrinks it so its longest side
  /// is at most max_side_px.
  virtual Status Detect(const cv::Mat& gray, const cv::Rect& roi,
                        std::vector<FaceBox>* faces, double scale = 0.0) = 0;
  /// The narrowest face box the detector finds in the copy it sees [px]:
  /// faces narrower than this / scale are missed.
  virtual double window_px() const = 0;

  static Status Create(const FaceDetectorOptions& options,
                       std::unique_ptr<FaceDetector>* out);
};

}  // namespace steadiface
