#pragma once

#include <cmath>
#include <functional>
#include <string>

#include <opencv2/core.hpp>

#include "steadiface_core/common/status.h"

namespace steadiface {
namespace eval {

/// Peer stabilizers run through the `ffmpeg` command line, for the
/// scorecard's baselines and the throughput comparison.
enum class FfmpegMethod {
  kVidstab,  ///< vidstabdetect then vidstabtransform (two passes), defaults
  kDeshake,  ///< deshake, defaults
};
const char* FfmpegMethodName(FfmpegMethod m);

/// True when `ffmpeg` is on PATH and has the vidstab and deshake filters;
/// `version` (optional) receives its first version line.
bool FfmpegAvailable(std::string* version);

/// Writes frames (bgr8, all the same size) to a lossless FFV1 Matroska file
/// through ffmpeg. Call `Write` per frame, then `Close`.
class LosslessVideoWriter {
 public:
  LosslessVideoWriter() = default;
  ~LosslessVideoWriter();
  LosslessVideoWriter(const LosslessVideoWriter&) = delete;
  LosslessVideoWriter& operator=(const LosslessVideoWriter&) = delete;

  Status Open(const std::string& path, int width, int height, double fps);
  Status Write(const cv::Mat& bgr);
  Status Close();

 private:
  FILE* pipe_ = nullptr;
  int width_ = 0, height_ = 0;
};

/// Decodes any video ffmpeg reads to bgr8 frames, handing each to `sink`;
/// `width`/`height` receive the size (from ffprobe).
Status ReadVideo(const std::string& path, const std::function<Status(const cv::Mat&)>& sink,
                 int* width, int* height);

/// Settings of a peer other than its defaults (for "best of its settings"
/// comparisons and for comparing at one field of view).
struct FfmpegPeerOptions {
  /// vidstabtransform's zoom [percent], with optzoom off: the output shows
  /// 1 - zoom/100 of the input's width (scaled by 1 / (1 - zoom/100) about
  /// its centre; measured, PeerAlignmentTest), so 30 is the default 0.70
  /// crop's view; NaN: its default (optzoom=1, the smallest static zoom
  /// that hides the borders of all but the strongest motion).
  double vidstab_zoom_percent = NAN;
  /// vidstabtransform's smoothing [frames each side]; < 0: its default (15).
  int vidstab_smoothing = -1;
};

/// Runs `method` with its default settings (or `peer`'s) on `input` (any video ffmpeg
/// reads; converted to yuv420p first, the format phone videos come in and
/// the one libvidstab handles — it aborts on packed or planar RGB),
/// decoding the stabilized frames to bgr8 and handing each to `sink`.
/// `work_dir` holds vidstab's transforms file while it runs (removed
/// afterwards). `seconds` receives
/// the wall time of the ffmpeg passes (including decoding the input and
/// handing frames over).
Status RunFfmpegStabilizer(FfmpegMethod method, const std::string& input, int width,
                           int height, const std::string& work_dir,
                           const std::function<Status(const cv::Mat&)>& sink,
                           double* seconds, const FfmpegPeerOptions& peer = FfmpegPeerOptions());

}  // namespace eval
}  // namespace steadiface
