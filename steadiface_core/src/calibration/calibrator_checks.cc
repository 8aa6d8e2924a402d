// The calibrator's refusals: a recording too short, too still, without
// enough tracked pairs or gyro, and a result the data do not determine.
#include "steadiface_core/calibration/calibrator.h"

#include <cmath>
#include <sstream>

#include "calibration/closed_form.h"

namespace steadiface {

using namespace calibration_internal;  // NOLINT: the calibrator's own steps

Status Calibrator::CheckLength(double duration_s) const {
  // Enough video and any IMU data at all.
  const CalibratorOptions& o = options_;
  if (frames_ < 2 || duration_s < o.min_duration_s) {
    std::ostringstream e;
    e << "calibrate: the recording is " << duration_s << " s long ("
      << frames_ << " frames); at least " << o.min_duration_s
      << " s of video is needed";
    return Status::Error(e.str());
  }
  if (gyro_.size() < 10) {
    return Status::Error(
        "calibrate: no IMU data (" + std::to_string(gyro_.size()) +
        " gyro samples); record the IMU topic with the images");
  }
  return Status::Ok();
}

Status Calibrator::CheckRecording(const GyroIntegral& g, double video_begin, double video_end,
                                  std::vector<const Pair*>* good_out, size_t* tracks_out,
                                  CalibrationResult* out) const {
  // The gyro covers the video, enough pairs have enough tracks, and the
  // camera turned enough; the good pairs and their track count.
  const CalibratorOptions& o = options_;
  CalibrationResult& res = *out;
  std::vector<const Pair*>& good = *good_out;
  size_t& tracks = *tracks_out;
  // The gyro must cover the video on the camera clock (t_imu = t_cam - offset).
  if (g.begin() > video_begin - initial_offset_s_ + 0.05 ||
      g.end() <
          video_end - initial_offset_s_ + shutter_.readout_time_s - 0.05) {
    std::ostringstream e;
    e << "calibrate: the IMU samples (" << g.end() - g.begin()
      << " s) do not cover the video with imu/time_offset " << initial_offset_s_
      << " s; check the IMU topic and the offset's sign";
    return Status::Error(e.str());
  }
  // Pairs with enough tracks.
  for (const Pair& p : pairs_) {
    if (static_cast<int>(p.ray_a.size()) >= o.min_tracks) {
      good.push_back(&p);
      tracks += p.ray_a.size();
    }
  }
  if (static_cast<int>(good.size()) < o.min_pairs) {
    std::ostringstream e;
    e << "calibrate: too few trackable features: " << good.size() << " of "
      << pairs_.size() << " frame pairs have " << o.min_tracks
      << " or more tracks (need " << o.min_pairs
      << "; a dark, blurred or textureless video?)";
    return Status::Error(e.str());
  }
  res.mean_angular_speed = MeanAngularSpeed(g, video_begin, video_end, initial_offset_s_);
  if (res.mean_angular_speed < o.min_angular_speed) {
    std::ostringstream e;
    e << "calibrate: too little rotation: the gyro's mean |omega| is "
      << res.mean_angular_speed << " rad/s, " << o.min_angular_speed
      << " rad/s or more is needed (shake or turn the camera for a few "
         "seconds)";
    return Status::Error(e.str());
  }
  return Status::Ok();
}

Status Calibrator::Determined(const CalibrationResult& res, bool have_cov) const {
  // The clock offset and the rotation must be determined.
  const CalibratorOptions& o = options_;
  if (!have_cov || !(res.time_offset_sigma_s <= o.max_offset_sigma_s)) {
    std::ostringstream e;
    e << "calibrate: the clock offset is not determined (1-sigma "
      << res.time_offset_sigma_s * 1e3 << " ms > " << o.max_offset_sigma_s * 1e3
      << " ms): more varied shake is needed";
    return Status::Error(e.str());
  }
  if (!(res.rotation_sigma_deg <= 2.0)) {
    std::ostringstream e;
    e << "calibrate: the IMU rotation is not determined (1-sigma "
      << res.rotation_sigma_deg
      << " deg > 2 deg): rotate the camera about more than one axis";
    return Status::Error(e.str());
  }
  return Status::Ok();
}

}  // namespace steadiface
