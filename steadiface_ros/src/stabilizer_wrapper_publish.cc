// StabilizerWrapper's output: the stabilized (or passed-through) image with
// its camera_info, landmarks, state, the transforms, rviz's extras and the
// debug image, each through the sink.
#include "steadiface_ros/stabilizer_wrapper.h"

#include <sensor_msgs/image_encodings.h>

#include "steadiface_core/pipeline/debug_overlay.h"
#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {

void StabilizerWrapper::PublishPassthrough(const Pending& p, const cv::Mat& image,
                                           const ros::Time& started) {
  // Without IMU data: the unstabilized frame, or nothing.
  if (!wrapper_options_.passthrough_without_imu) {
    ++counters_.dropped_no_gyro;
    sink_->Error("no_imu", "no IMU data: frame dropped (passthrough_without_imu: false)");
    return;
  }
  steadiface::PipelineFrame frame;
  const steadiface::Status s = pipeline_->Passthrough(image, &frame);
  if (!s.ok()) {
    ++counters_.dropped_pipeline_error;
    return;
  }
  ++counters_.passthrough;
  sink_->Error("no_imu", "no IMU data: publishing unstabilized frames");
  scheduler_.OnFrameDone(ToCoreTime(p.image->header.stamp));
  FinishHeld();  // in order
  Publish(p, frame, image, false, true, started);
}

void StabilizerWrapper::Publish(const Pending& p, const steadiface::PipelineFrame& frame,
                                const cv::Mat& input, bool extrapolated, bool passthrough,
                                const ros::Time& started) {
  std_msgs::Header in_header = p.image->header;
  const std::string camera_frame =
      wrapper_options_.camera_frame.empty() ? in_header.frame_id : wrapper_options_.camera_frame;
  std_msgs::Header out_header = in_header;
  out_header.frame_id = camera_frame + wrapper_options_.stabilized_suffix;
  PublishOutputImage(frame, out_header);
  const ros::Time published = sink_->Now();
  if (!passthrough) {
    std_msgs::Header lm_header = in_header;
    lm_header.frame_id = camera_frame;
    PublishLandmarksAndState(p, frame, lm_header, extrapolated, started, published);
    PublishTransforms(frame, in_header, camera_frame, out_header);
    PublishRvizExtras(frame, lm_header, out_header);
    if (sink_->WantsDebugImage()) PublishDebugImage(frame, input, in_header);
    UpdateStatus(frame, in_header);
  }
  ++counters_.frames_out;
}

void StabilizerWrapper::PublishOutputImage(const steadiface::PipelineFrame& frame,
                                           const std_msgs::Header& out_header) {
  if (!frame.output.empty()) {
    sensor_msgs::CameraInfoPtr info(
        new sensor_msgs::CameraInfo(ToCameraInfo(frame.output_intrinsics, out_header)));
    if (sink_->WantsImage()) {
      const std::string enc = frame.output.channels() == 1
                                  ? sensor_msgs::image_encodings::MONO8
                                  : frame.output.channels() == 4
                                        ? sensor_msgs::image_encodings::BGRA8
                                        : sensor_msgs::image_encodings::BGR8;
      sink_->PublishImage(ToImageMsg(out_header, enc, frame.output), info);
    } else {
      sink_->PublishOutputInfo(info);
    }
  }
}

void StabilizerWrapper::PublishLandmarksAndState(const Pending& p,
                                                 const steadiface::PipelineFrame& frame,
                                                 const std_msgs::Header& lm_header,
                                                 bool extrapolated, const ros::Time& started,
                                                 const ros::Time& published) {
  const std_msgs::Header& in_header = p.image->header;
  sink_->PublishLandmarks(ToMsg(frame.face, lm_header));
  steadiface::StabilizerState state = ToMsg(frame, lm_header, extrapolated);
  if (!published.isZero() && published >= in_header.stamp) {
    state.latency_ms = (published - in_header.stamp).toSec() * 1e3;
    if (!p.received.isZero() && p.received >= in_header.stamp) {
      state.arrival_latency_ms = (p.received - in_header.stamp).toSec() * 1e3;
    }
    if (!started.isZero() && !p.received.isZero() && started >= p.received) {
      state.gyro_wait_ms = (started - p.received).toSec() * 1e3;
    }
  }
  sink_->PublishState(state);
}

std::string StabilizerWrapper::WorldFrame(const std::string& camera_frame) const {
  return wrapper_options_.world_frame.empty() ? camera_frame + "_world"
                                              : wrapper_options_.world_frame;
}

void StabilizerWrapper::PublishTransforms(const steadiface::PipelineFrame& frame,
                                          const std_msgs::Header& in_header,
                                          const std::string& camera_frame,
                                          const std_msgs::Header& out_header) {
  // TF, strictly increasing within an epoch.
  if (last_tf_stamp_.isZero() || in_header.stamp > last_tf_stamp_) {
    std::vector<geometry_msgs::TransformStamped> tf;
    geometry_msgs::TransformStamped t;
    t.header.stamp = in_header.stamp;
    t.header.frame_id = camera_frame;
    t.child_frame_id = out_header.frame_id;
    // Child (virtual) coordinates -> parent (real) coordinates: R_r R_v^-1.
    const Eigen::Quaterniond rel =
        (frame.stabilizer.R_r * frame.stabilizer.R_v.conjugate()).normalized();
    t.transform = ToTransformMsg(rel);
    if (rel.coeffs().allFinite()) tf.push_back(t);
    if (frame.stabilizer.background.valid) {
      // The background layer's virtual camera beside the subject's.
      geometry_msgs::TransformStamped bt = t;
      bt.child_frame_id = out_header.frame_id + "_background";
      const Eigen::Quaterniond brel =
          (frame.stabilizer.R_r * frame.stabilizer.background.R_v.conjugate()).normalized();
      bt.transform = ToTransformMsg(brel);
      if (brel.coeffs().allFinite()) tf.push_back(bt);
    }
    if (wrapper_options_.publish_world_tf) {
      // The integrated gyro as a child of the camera frame, which keeps the
      // parent its driver or URDF gives it: world coordinates -> camera
      // coordinates, R_r.
      geometry_msgs::TransformStamped w;
      w.header.stamp = in_header.stamp;
      w.header.frame_id = camera_frame;
      w.child_frame_id = WorldFrame(camera_frame);
      const Eigen::Quaterniond q_cw = frame.stabilizer.R_r.normalized();
      w.transform = ToTransformMsg(q_cw);
      if (q_cw.coeffs().allFinite()) tf.push_back(w);
    }
    sink_->PublishTf(tf);
    last_tf_stamp_ = in_header.stamp;
  } else {
    ++counters_.tf_skipped;
  }
}

void StabilizerWrapper::PublishRvizExtras(const steadiface::PipelineFrame& frame,
                                          const std_msgs::Header& in_header,
                                          const std_msgs::Header& out_header) {
  // rviz frusta: camera -> world orientations are the inverses of R_r, R_v.
  frusta_.Add(frame.stabilizer.R_r.conjugate(), frame.stabilizer.R_v.conjugate());
  if (sink_->WantsMarkers()) {
    std_msgs::Header world_header = in_header;
    world_header.frame_id = WorldFrame(in_header.frame_id);  // (the camera frame)
    const visualization_msgs::MarkerArray m = frusta_.Make(
        world_header, pipeline_->camera_model().intrinsics(), frame.output_intrinsics);
    if (!m.markers.empty()) sink_->PublishMarkers(m);
  }
  if (frame.stabilizer.has_target) {
    // H's ray in the virtual camera: K_v(t)^-1 [H; 1].
    const Eigen::Vector3d ray = (pipeline_->camera_model().VirtualK(frame.stabilizer.t).inverse() *
                                 frame.stabilizer.H.homogeneous())
                                    .normalized();
    if (ray.allFinite()) {
      geometry_msgs::PointStamped p;
      p.header = out_header;
      p.point.x = ray.x();
      p.point.y = ray.y();
      p.point.z = ray.z();
      sink_->PublishHeadTarget(p);
    }
  }
}

void StabilizerWrapper::PublishDebugImage(const steadiface::PipelineFrame& frame,
                                          const cv::Mat& input,
                                          const std_msgs::Header& in_header) {
  cv::Mat dbg;
  steadiface::DrawDebugOverlay(input, pipeline_->camera_model(),
                               pipeline_->stabilizer().protrusion(), &frame.face,
                               &frame.stabilizer, &dbg);
  if (frame.layered.active) {
    const steadiface::OutputGeometry& og = pipeline_->warper().output_geometry();
    steadiface::DrawLayeredOverlay(frame.mesh.source.empty() ? pipeline_->warper().mesh()
                                                             : frame.mesh,
                                   frame.layered.region,
                                   frame.layered.blend, og.width(), og.height(), &dbg);
  }
  if (frame.composite.active && pipeline_->compositor() != nullptr) {
    // The warper's last mesh is the background layer's (rendered second).
    steadiface::DrawCompositeOverlay(pipeline_->warper().mesh(), *pipeline_->compositor(), &dbg);
  }
  sink_->PublishDebugImage(
      ToImageMsg(in_header, sensor_msgs::image_encodings::BGR8, dbg));
}

}  // namespace steadiface_ros
