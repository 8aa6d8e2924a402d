#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/visual/visual_rotation.h"

namespace steadiface {

struct VideoReadoutOptions {
  /// The readout the video is first read with [s]; NaN: half the frame
  /// interval (from the first two stamps).
  double nominal_readout_s = NAN;
  /// Frame triples with a trusted rotation needed [count].
  int min_triples = 30;
  /// The fit must explain this much of the rows' spread [-] ...
  double min_correlation = 0.5;
  /// ... and leave the readout this certain (1 sigma) [s].
  double max_sigma_s = 0.003;
};

struct VideoReadoutResult {
  bool determined = false;
  double readout_s = NAN;  ///< the estimate (also when not determined)
  double sigma_s = NAN;    ///< its formal 1-sigma [s]
  int triples = 0;         ///< frame triples used [count]
  double correlation = 0.0;
  /// The low-passed shake's RMS frequency [Hz] (the small correction made
  /// for it: x / sin(x), x = 2 pi f times the frame interval).
  double shake_hz = 0.0;
  std::string reason;  ///< why not determined (empty when it is)
};

/// The rolling-shutter readout from the video alone, for a camera without
/// an IMU. The rotation from the video (visual/visual_rotation.h) is fitted
/// per frame pair with the readout read as `r0`: how the angular velocity
/// changes across one frame's rows is seen only as (its rate of change) x
/// (the readout), so the fitted rate of change is the true one times r / r0.
/// The true one is also seen across frames: the angular velocity of the
/// next pair minus that of the previous, over the time between them. The
/// ratio of the two over a recording with hand shake gives r = r0 x slope
/// (least squares through the origin, outliers beyond 3 robust sigma
/// dropped). A still or smoothly panning camera does not determine it: the
/// result then says why. Offline; not thread-safe.
class VideoReadoutEstimator {
 public:
  static Status Create(const CameraIntrinsics& intrinsics, const RollingShutterOptions& shutter,
                       const VideoReadoutOptions& options,
                       std::unique_ptr<VideoReadoutEstimator>* out);
  /// One frame, in time order: 8-bit grey at the intrinsics' size.
  Status AddFrame(const cv::Mat& grey, Time stamp);
  VideoReadoutResult Estimate() const;
  int frames() const { return frames_; }

 private:
  VideoReadoutEstimator(const CameraIntrinsics& intrinsics, const RollingShutterOptions& shutter,
                        const VideoReadoutOptions& options);
  Status Start(Time stamp);  // the estimator at the nominal readout

  const CameraIntrinsics intrinsics_;
  const RollingShutterOptions shutter_;
  const VideoReadoutOptions options_;
  double r0_ = NAN;
  std::unique_ptr<VisualRotationEstimator> visual_;
  std::vector<VisualRotation> pairs_;  // per frame after the first
  // The first frame, kept until the second gives the frame interval.
  cv::Mat first_;
  Time first_stamp_;
  int frames_ = 0;
};

}  // namespace steadiface
