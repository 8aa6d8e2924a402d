// The pipeline's rotation sources: gyro samples into the timeline (held
// back after frames rotated by the video until the video reaches them),
// the rotation from the video written into it as orientations, and the
// gyro-vs-video check's clock offset applied to it.
#include "steadiface_core/pipeline/pipeline.h"

#include <algorithm>
#include <cmath>

#include "steadiface_core/common/so3.h"

namespace steadiface {

SampleResult Pipeline::AddGyro(const GyroSample& sample) {
  // kVisual: the video gives the rotation.
  if (options_.rotation_source == RotationSource::kVisual) return SampleResult::kAccepted;
  if (video_newest_) {
    // kAuto after frames from the video: held back until the video reaches
    // it (HandBackToGyro), at most a few seconds of samples.
    if (!sample.angular_velocity.allFinite()) return timeline_.AddSample(sample);  // counted
    if (pending_gyro_.size() >= kMaxPendingGyro) pending_gyro_.pop_front();
    pending_gyro_.push_back(sample);
    return SampleResult::kAccepted;
  }
  return timeline_.AddSample(sample);
}

void Pipeline::HandBackToGyro() {
  // The samples the video's nodes already passed are not needed.
  while (!pending_gyro_.empty() &&
         timeline_.CameraTime(pending_gyro_.front().stamp) <= timeline_.newest()) {
    pending_gyro_.pop_front();
  }
  if (pending_gyro_.size() < 2) return;
  const Duration spacing = pending_gyro_[1].stamp - pending_gyro_[0].stamp;
  if (timeline_.CameraTime(pending_gyro_.front().stamp) - timeline_.newest() > spacing * 3 / 2) {
    return;  // the video has not reached the gyro yet
  }
  video_newest_ = false;
  for (const GyroSample& g : pending_gyro_) timeline_.AddSample(g);
  pending_gyro_.clear();
}

bool Pipeline::GyroCovers(Time stamp) const {
  if (options_.rotation_source == RotationSource::kVisual) return true;
  return timeline_.Covers(timing_.FirstRowTime(stamp)) &&
         timeline_.Covers(timing_.LastRowTime(stamp));
}

void Pipeline::ApplyOffsetEstimate(Time stamp) {
  // The correction follows the check's estimate from the next frame on
  // (this frame's rows were covered under the old one), rate-limited; it
  // holds while the check cannot judge or blames the rotation.
  const GyroVideoCheckOptions& o = options_.gyro_video_check;
  const double dt = has_check_stamp_ ? ToSeconds(stamp - check_stamp_) : 0.0;
  has_check_stamp_ = true;
  check_stamp_ = stamp;
  const GyroVideoCheckResult& r = check_->result();
  if (!r.judged || r.rotation_contradicts || !(dt > 0.0)) return;
  const double target =
      std::max(-o.offset_range_s, std::min(o.offset_range_s, r.offset_correction_s));
  const double step = o.apply_rate_s_per_s * std::min(dt, 0.2);
  const double now = timeline_.offset_correction();
  timeline_.set_offset_correction(now + std::max(-step, std::min(step, target - now)));
}

Status Pipeline::VisualStep(const cv::Mat& grey, Time stamp, PipelineFrame* f) {
  Status s = visual_->Process(grey, stamp, last_face_box_, &f->visual);
  if (!s.ok()) return s;
  const Time first_row = timing_.FirstRowTime(stamp);
  const Time last_row = timing_.LastRowTime(stamp);
  // kVisual: the first frame, or one that starts before the newest node
  // (time ran back), starts the timeline afresh, the camera held still over
  // it. kAuto continues the gyro's timeline (the owner resets the stream
  // when time runs back).
  const bool visual_only = options_.rotation_source == RotationSource::kVisual;
  if (visual_only && !timeline_.empty() && timeline_.newest() >= first_row) timeline_.Reset();
  if (timeline_.empty() || !has_visual_mid_) {
    if (timeline_.empty()) {
      timeline_.AddOrientation(first_row - FromSeconds(1e-3), Eigen::Quaterniond::Identity(),
                               Eigen::Vector3d::Zero());
    }
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    timeline_.CameraToWorld(timeline_.newest(), &q);
    if (last_row > timeline_.newest()) timeline_.AddOrientation(last_row, q, Eigen::Vector3d::Zero());
    return Status::Ok();
  }
  if (last_row <= timeline_.newest()) return Status::Ok();  // the gyro covers it after all
  // The rotation between the two frames' middle rows and across this
  // frame's rows is the pair's (its omega(t) integrated), from the
  // orientation at the previous frame's middle row: nodes every 2 ms from
  // the newest (the previous frame's last row, or the gyro's newest sample)
  // to this frame's last row. Rows already used keep the rotations they
  // were given; the blanking between the frames takes up any difference.
  // Not trusted: held still from the newest node.
  const bool held = !f->visual.valid;
  const Time anchor_t = held ? timeline_.newest() : visual_mid_;
  Eigen::Quaterniond anchor = Eigen::Quaterniond::Identity();
  if (!QuerySucceeded(timeline_.CameraToWorld(anchor_t, &anchor))) {
    timeline_.CameraToWorld(timeline_.newest(), &anchor);
  }
  const double ta = ToSeconds(anchor_t - f->visual.stamp);
  const Time from = timeline_.newest();
  const int steps = std::max(1, static_cast<int>(std::ceil(ToSeconds(last_row - from) / 0.002)));
  for (int k = 1; k <= steps; ++k) {
    const Time t = from + (last_row - from) * k / steps;
    const double u = ToSeconds(t - f->visual.stamp);
    timeline_.AddOrientation(t, anchor * ExpSO3(f->visual.Turn(ta, u)), f->visual.RateAt(u));
  }
  return Status::Ok();
}

}  // namespace steadiface
