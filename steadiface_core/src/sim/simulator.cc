#include "steadiface_core/sim/simulator.h"

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/ramp.h"
#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace sim {

const std::vector<std::string>& PresetNames() {
  static const std::vector<std::string> names = {
      "still", "walk", "pan", "run", "occlusion", "two_faces", "turn_away", "vlog", "shake",
      "drift", "walk_across", "bob", "hair", "passer_by", "robot", "roll",
      "low_texture", "dropout"};
  return names;
}

namespace {

// The walking-selfie base.
void Walking(SimulatorOptions* o) {
  o->camera.shake_rms_rad = 0.012;
  o->camera.translation_rms_m = 0.002;
  o->camera.pan_rate = 0.0;
  o->body_bob_m = 0.02;
  o->body_sway_m = 0.01;
}

// Handheld by someone standing: a small tremor (0.15 deg RMS per axis), the
// subject with neck and shoulders.
void StandingTremor(SimulatorOptions* o) {
  o->camera.shake_rms_rad = 0.15 * M_PI / 180.0;
  o->camera.translation_rms_m = 0.001;
  o->camera.pan_rate = 0.0;
  o->body_bob_m = o->body_sway_m = 0.0;
  o->render_torso = true;
}

// The background photo with the options' contrast and blur.
cv::Mat Plain(const cv::Mat& photo, const SimulatorOptions& o) {
  if (o.background_contrast == 1.0 && o.background_blur_px <= 0.0) return photo;
  cv::Mat out;
  const cv::Scalar mean = cv::mean(photo);
  photo.convertTo(out, CV_32FC3);
  out = (out - mean) * o.background_contrast + mean;
  if (o.background_blur_px > 0.0) cv::GaussianBlur(out, out, cv::Size(), o.background_blur_px);
  out.convertTo(out, CV_8UC3);
  return out;
}

// The presets that differ by the camera's motion; false for another name.
bool ApplyCameraPreset(const std::string& name, SimulatorOptions* o) {
  if (name == "still") {
    o->camera.shake_rms_rad = 0.0;
    o->camera.translation_rms_m = 0.0;
    o->body_bob_m = o->body_sway_m = 0.0;
    o->head.bob_amplitude_m = 0.01;
    o->head.sway_amplitude_m = 0.012;
  } else if (name == "walk") {
    Walking(o);
  } else if (name == "pan") {
    o->camera.shake_rms_rad = 0.004;
    o->camera.translation_rms_m = 0.001;
    o->camera.pan_rate = 0.2;
    o->body_bob_m = o->body_sway_m = 0.0;
  } else if (name == "run") {
    Walking(o);
    o->use_real_gyro = true;
    o->body_bob_m = 0.04;
    o->body_bob_hz = 2.6;
    o->camera.translation_rms_m = 0.004;
  } else if (name == "shake") {
    // Strong real shake: the recorded running trace scaled up, a grey
    // picture, motion blur and a slow rolling shutter.
    Walking(o);
    o->use_real_gyro = true;
    o->real_gyro_scale = 3.0;
    o->body_bob_m = 0.04;
    o->body_bob_hz = 2.6;
    o->camera.translation_rms_m = 0.004;
    o->grayscale = true;
    o->exposure_s = 0.025;
    o->readout_s = 0.03;
  } else if (name == "roll") {
    // A walking selfie whose horizon tilts by +-10 deg at 0.2 Hz.
    Walking(o);
    o->camera.roll_amplitude_rad = 10.0 * M_PI / 180.0;
    o->camera.roll_hz = 0.2;
  } else if (name == "low_texture") {
    // A walking selfie in front of a pale, plain wall: the building at 20 %
    // of its contrast, softened: the rotation from the video finds about a
    // third of its usual features (sparse, not blind).
    Walking(o);
    o->background_contrast = 0.2;
    o->background_blur_px = 1.0;
  } else if (name == "dropout") {
    // A walking selfie whose IMU drops out from 3 s to 5 s, in a sequence
    // of at least 7 s (2 s after the IMU's return).
    Walking(o);
    o->duration_s = std::max(o->duration_s, 7.0);
    o->imu_dropout_start_s = 3.0;
    o->imu_dropout_end_s = 5.0;
  } else if (name == "robot") {
    // A legged robot's head camera (its own sensor: 640x480, 60 deg
    // horizontal field, whatever the size asked for) vibrating with the gait
    // at 7-9 Hz, 0.5 deg RMS per axis; a person standing 2.5 m away, with
    // neck and shoulders: the face about 33 px wide.
    o->width = 640;
    o->height = 480;
    o->hfov_rad = M_PI / 3.0;
    o->camera.shake_rms_rad = 0.5 * M_PI / 180.0;
    o->camera.shake_lo_hz = 7.0;
    o->camera.shake_hi_hz = 9.0;
    o->camera.translation_rms_m = 0.002;
    o->camera.pan_rate = 0.0;
    o->body_bob_m = o->body_sway_m = 0.0;
    o->head.distance_m = 2.5;
    o->render_torso = true;
  } else {
    return false;
  }
  return true;
}

// The presets that differ by the subject; false for another name.
bool ApplySubjectPreset(const std::string& name, SimulatorOptions* o) {
  if (name == "occlusion") {
    Walking(o);
    o->occlusion_start_s = 0.35 * o->duration_s;
    o->occlusion_end_s = 0.6 * o->duration_s;
  } else if (name == "two_faces") {
    Walking(o);
    o->second_face_start_s = 0.25 * o->duration_s;
    o->second_face_final_distance_m = 0.4;
  } else if (name == "vlog") {
    Walking(o);
    o->render_torso = true;
    o->head.distance_m = 0.7;
  } else if (name == "turn_away") {
    Walking(o);
    o->head.yaw_amplitude_rad = 1.2;
    o->head.yaw_hz = 0.5 / std::max(1.0, o->duration_s);
  } else if (name == "drift") {
    // The head drifts several cm against the scene and turns (yaw 12 deg
    // RMS).
    StandingTremor(o);
    o->head.distance_m = 0.6;
    o->head.drift_amplitude_m = 0.05;
    o->head.drift_hz = 0.2;
    o->head.yaw_amplitude_rad = std::sqrt(2.0) * 12.0 * M_PI / 180.0;
    o->head.yaw_hz = 0.3;
  } else if (name == "bob") {
    // A walking selfie whose head bobs against the scene by +-100 px at
    // 720p (+-0.057 m at 0.6 m, 1.8 Hz; sideways 0.02 m at 0.9 Hz), with neck
    // and shoulders: more than any mesh band can absorb.
    Walking(o);
    o->render_torso = true;
    o->head.distance_m = 0.6;
    o->head.bob_amplitude_m = 0.057;
    o->head.sway_amplitude_m = 0.02;
  } else if (name == "hair") {
    // vlog, with hair strands at the head's top edge.
    Walking(o);
    o->render_torso = true;
    o->head.distance_m = 0.7;
    o->hair_edge = true;
  } else if (name == "passer_by") {
    // A walking selfie with neck and shoulders; a person walks across the
    // view 2.5 m away, behind the subject, in the middle of the sequence.
    Walking(o);
    o->render_torso = true;
    o->passer_by_start_s = 0.15 * o->duration_s;
    o->passer_by_end_s = 0.85 * o->duration_s;
  } else if (name == "walk_across") {
    // The subject walks across the view, 0.9 m away, from 0.35 m left of
    // the centre to 0.35 m right of it over the sequence.
    StandingTremor(o);
    o->head.distance_m = 0.9;
    o->head.bob_amplitude_m = 0.02;
    o->head.walk_start_x_m = -0.35;
    o->head.walk_speed_m_s = 0.7 / std::max(0.1, o->duration_s);
  } else {
    return false;
  }
  return true;
}

}  // namespace

Status ApplyPreset(const std::string& name, SimulatorOptions* o) {
  if (ApplyCameraPreset(name, o) || ApplySubjectPreset(name, o)) return Status::Ok();
  std::string all;
  for (const auto& n : PresetNames()) all += " " + n;
  return Status::Error("unknown preset '" + name + "'; presets:" + all);
}

Status LoadDeepFvsGyro(const std::string& path, std::vector<GyroSample>* out) {
  std::ifstream in(path);
  if (!in) return Status::Error("cannot open gyro log '" + path + "'");
  out->clear();
  std::string line;
  double t0 = -1;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    double t_us, gx, gy, gz;
    if (!(ss >> t_us >> gx >> gy >> gz)) continue;
    if (t0 < 0) t0 = t_us;
    out->push_back({Time(FromSeconds((t_us - t0) * 1e-6)), Eigen::Vector3d(gy, gx, -gz)});
  }
  if (out->size() < 10) return Status::Error("gyro log '" + path + "' has too few samples");
  return Status::Ok();
}

Simulator::Simulator(const SimulatorOptions& o)
    : options_(o),
      intrinsics_(IntrinsicsFromHorizontalFov(o.width, o.height, o.hfov_rad)),
      timing_([&o] {
        RollingShutterOptions rs;
        rs.readout_time_s = o.readout_s;
        return rs;
      }(), o.height),
      camera_([&o] {
        CameraMotionOptions c = o.camera;
        c.seed = o.seed * 7919 + 1;
        return c;
      }()),
      head_([&o] {
        HeadMotionOptions h = o.head;
        h.seed = o.seed * 7919 + 2;
        return h;
      }()) {}

Status Simulator::Create(const SimulatorOptions& options, std::unique_ptr<Simulator>* out) {
  const SimulatorOptions& o = options;
  if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192) {
    return Status::Error("sim: image size must be in [16, 8192] px");
  }
  if (!(o.fps > 0 && o.fps <= 1000) || !(o.duration_s > 0 && o.duration_s <= 3600) ||
      !(o.hfov_rad > 0.1 && o.hfov_rad < 3.0) || !(o.readout_s >= 0 && o.readout_s < 0.2) ||
      !(o.imu_rate_hz >= 10 && o.imu_rate_hz <= 10000) || o.band_rows < 1) {
    return Status::Error("sim: fps, duration, hfov, readout, imu rate or band rows out of range");
  }
  if (!(o.exposure_s >= 0.0 && o.exposure_s <= 1.0 / o.fps) || o.exposure_samples < 1 ||
      o.exposure_samples > 64) {
    return Status::Error("sim: exposure must be in [0, 1/fps] s with 1-64 samples");
  }
  if (!(o.real_gyro_scale > 0.0 && o.real_gyro_scale <= 10.0) ||
      !(o.real_gyro_speed > 0.0 && o.real_gyro_speed <= 10.0)) {
    return Status::Error("sim: real_gyro_scale and real_gyro_speed must be in (0, 10]");
  }
  if (o.head_model != "relief" && o.head_model != "flat") {
    return Status::Error("sim: head_model must be relief or flat");
  }
  if (!(o.relief.pivot_depth_m > 0.0 && o.relief.pivot_depth_m < 0.5) ||
      !(o.relief.outline_radius > 0.1 && o.relief.outline_radius <= 1.0) ||
      !(std::abs(o.relief.nose_height_m) < 0.1) || !(o.relief.nose_sigma_x > 0.0) ||
      !(o.relief.nose_sigma_y > 0.0) || !std::isfinite(o.relief.nose_below) ||
      !(o.relief.breadth_face_widths >= 0.0 && o.relief.breadth_face_widths <= 5.0) ||
      !(o.relief.mean_face_sigma > 0.0 && o.relief.mean_face_sigma <= 0.5)) {
    return Status::Error(
        "sim: relief pivot depth in (0, 0.5) m, outline radius in (0.1, 1], "
        "nose height under 0.1 m, nose sigmas positive, breadth in [0, 5] face widths, "
        "mean-face sigma in (0, 0.5] face widths");
  }
  if (!(o.background_contrast > 0.0 && o.background_contrast <= 1.0) ||
      !(o.background_blur_px >= 0.0 && o.background_blur_px <= 50.0)) {
    return Status::Error("sim: background_contrast must be in (0, 1], background_blur_px in [0, 50]");
  }
  std::unique_ptr<Simulator> s(new Simulator(options));
  Status st = s->Init();
  if (!st.ok()) return st;
  *out = std::move(s);
  return Status::Ok();
}

Status Simulator::Init() {
  const SimulatorOptions& o = options_;
  num_frames_ = static_cast<int>(std::floor(o.duration_s * o.fps + 1e-9));
  const cv::Mat photo = cv::imread(o.data_dir + "/" + o.face_photo, cv::IMREAD_COLOR);
  const cv::Mat bg = cv::imread(o.data_dir + "/" + o.background_photo, cv::IMREAD_COLOR);
  if (photo.empty() || bg.empty()) {
    return Status::Error("sim: cannot read " + o.data_dir + "/" + o.face_photo + " or " +
                         o.background_photo);
  }
  background_.reset(new InfiniteBackground(Plain(bg, o), 0.8 * intrinsics_.fx));
  const double m_per_px = o.face_width_m / o.face_width_px;
  face_ = MakeFaceBillboard(photo, o.face_region, o.face_region.width * m_per_px);
  face_centre_uv_ = o.face_centre_px - Eigen::Vector2d(o.face_region.x, o.face_region.y);
  const Eigen::Vector2d centre = (face_centre_uv_ - face_.anchor_px) * face_.metres_per_px;
  face_front_ = Eigen::Vector3d(centre.x(), centre.y(), 0.0);
  if (o.head_model == "relief") {
    const Status st = MakeRelief(m_per_px);
    if (!st.ok()) return st;
    turning_centre_ = face_front_ + Eigen::Vector3d(0.0, 0.0, o.relief.pivot_depth_m);
  }
  face_.pose = [this](double t) { return FacePose(t, true); };
  if (o.hair_edge) MakeHair();
  MakeTorso();
  MakeSecondFaceAndOccluder(photo, m_per_px);
  MakePasserBy();
  if (o.use_real_gyro) {
    const Status st = LoadRealGyro();
    if (!st.ok()) return st;
  }
  SynthesizeImu();
  return Status::Ok();
}

Status Simulator::LoadRealGyro() {
  // The recorded trace, scaled, replayed as the camera's rotation.
  const SimulatorOptions& o = options_;
  std::vector<GyroSample> raw;
  Status st = LoadDeepFvsGyro(o.data_dir + "/gyro/gyro_log_144425_189635.txt", &raw);
  if (!st.ok()) return st;
  OrientationTimelineOptions to;
  to.buffer_duration_s = 600.0;
  to.max_samples = 10000000;
  to.max_extrapolation_s = 0.0;
  real_gyro_.reset(new OrientationTimeline(to));
  for (auto& g : raw) {
    g.angular_velocity *= o.real_gyro_scale;
    real_gyro_->AddSample(g);
  }
  real_gyro_span_s_ = ToSeconds(real_gyro_->newest()) - 0.01;
  return Status::Ok();
}

void Simulator::SynthesizeImu() {
  // The gyro samples: the true rate plus bias, noise, stamp jitter and the
  // IMU clock's offset.
  const SimulatorOptions& o = options_;
  std::mt19937_64 rng(options_.seed * 104729 + 3);
  std::normal_distribution<double> n01(0.0, 1.0);
  // The accelerometer's noise from its own engine and distribution (a
  // normal distribution caches every other draw): the gyro's samples stay
  // what they were before there was an accelerometer.
  std::mt19937_64 rng_accel(options_.seed * 7919 + 11);
  std::normal_distribution<double> n01_accel(0.0, 1.0);
  const double t_end = o.duration_s + o.readout_s + 0.06;
  const int n = static_cast<int>(t_end * o.imu_rate_hz) + 1;
  imu_.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double t = i / o.imu_rate_hz;
    Eigen::Vector3d w;
    if (real_gyro_) {
      double sign = 1.0;
      real_gyro_->AngularVelocity(Time(FromSeconds(RealGyroTime(t, &sign))), &w);
      w *= sign * o.real_gyro_speed;
    } else {
      w = camera_.AngularVelocity(t);
    }
    w += o.gyro_bias + o.gyro_noise * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    const double jitter = o.imu_jitter_s * n01(rng);
    const double clamp = 0.4 / o.imu_rate_hz;  // keep stamps ordered
    const double stamp = t + std::max(-clamp, std::min(clamp, jitter)) - o.imu_clock_offset_s;
    // A dropout loses the samples, after their noise was drawn: every other
    // sample is what it is without the dropout.
    const bool lost = t >= o.imu_dropout_start_s && t < o.imu_dropout_end_s;
    if (!lost) imu_.push_back({Time(FromSeconds(stamp)), w});
    // The specific force in the camera: R^T (acceleration - gravity), the
    // acceleration by central differences of the true position.
    const double h = 1e-3;
    const Pose P = CameraPose(t);
    const Eigen::Vector3d acc =
        (CameraPose(t + h).p - 2.0 * P.p + CameraPose(t - h).p) / (h * h);
    const Eigen::Vector3d gravity(0.0, kStandardGravity, 0.0);
    const Eigen::Vector3d f = P.R.conjugate() * (acc - gravity) +
                              o.accel_noise * Eigen::Vector3d(n01_accel(rng_accel), n01_accel(rng_accel),
                                                              n01_accel(rng_accel));
    if (!lost) accel_.push_back({Time(FromSeconds(stamp)), f});
  }
}

Eigen::Vector3d Simulator::UpInCamera(double t) const {
  return CameraPose(t).R.conjugate() * Eigen::Vector3d(0.0, -1.0, 0.0);
}

Eigen::Vector3d Simulator::Body(double t) const {
  const double w = 2.0 * M_PI * options_.body_bob_hz;
  return Eigen::Vector3d(options_.body_sway_m * std::sin(0.5 * w * t),
                         options_.body_bob_m * std::sin(w * t), 0.0);
}

double Simulator::RealGyroTime(double t, double* sign) const {
  // Longer sequences play the trace forwards, then backwards (a smooth,
  // continuous orientation path; angular velocity flips sign).
  const double T = real_gyro_span_s_;
  double u = std::fmod(std::max(0.0, t * options_.real_gyro_speed), 2.0 * T);
  *sign = 1.0;
  if (u > T) {
    u = 2.0 * T - u;
    *sign = -1.0;
  }
  return u;
}

Pose Simulator::Orbit(const Pose& P, double t) const {
  if (!options_.pan_orbits_head || options_.camera.pan_rate == 0.0) return P;
  const Eigen::Quaterniond R_pan(
      Eigen::AngleAxisd(camera_.PanAngle(t), Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d pivot(0.0, 0.0, options_.head.distance_m);
  Pose out;
  out.R = R_pan * P.R;
  out.p = pivot + R_pan * (P.p - pivot);
  return out;
}

Pose Simulator::CameraPose(double t) const {
  Pose C;
  if (real_gyro_) {
    double sign = 1.0;
    real_gyro_->CameraToWorld(Time(FromSeconds(RealGyroTime(t, &sign))), &C.R);
  } else {
    C.R = camera_.Orientation(t);  // includes the pan
  }
  C.p = camera_.Position(t) + Body(t);
  if (options_.pan_orbits_head && options_.camera.pan_rate != 0.0 && !real_gyro_) {
    const Eigen::Quaterniond R_pan(
        Eigen::AngleAxisd(camera_.PanAngle(t), Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d pivot(0.0, 0.0, options_.head.distance_m);
    C.p = pivot + R_pan * (C.p - pivot);
  }
  return C;
}

Time Simulator::Stamp(int i) const { return Time(FromSeconds(0.05 + i / options_.fps)); }

double Simulator::RowTimeS(Time stamp, double y) const {
  return ToSeconds(timing_.RowTime(stamp, y));
}

SimTruth Simulator::Truth(int i) const {
  SimTruth tr;
  tr.stamp = Stamp(i);
  const CameraIntrinsics& k = intrinsics_;
  const int n_rows = 16;
  for (int r = 0; r < n_rows; ++r) {
    const double y = r * (k.height - 1.0) / (n_rows - 1);
    tr.rotation_rows.push_back(y);
    tr.R_r.push_back(CameraPose(RowTimeS(tr.stamp, y)).R.conjugate());
  }
  auto row_time = [&](double y) { return RowTimeS(tr.stamp, y); };
  auto cam = [this](double t) { return CameraPose(t); };
  const bool visible = ProjectRollingShutter(k, row_time, cam, [&](double t) {
    const Pose P = FacePose(t, false);
    return Eigen::Vector3d(P.R * face_front_ + P.p);
  }, &tr.head_px);
  tr.head_in_view = options_.render_face && visible && tr.head_px.x() >= 0 && tr.head_px.y() >= 0 &&
                    tr.head_px.x() <= k.width - 1 && tr.head_px.y() <= k.height - 1;
  ProjectRollingShutter(k, row_time, cam, [&](double t) {
    const Pose P = FacePose(t, true);
    return Eigen::Vector3d(P.R * face_front_ + P.p);
  }, &tr.face_px);
  Eigen::Vector2d a, b;
  const double half = 0.5 * options_.face_width_px;
  if (ProjectRollingShutter(k, row_time, cam, [&](double t) {
        return face_.WorldPoint(face_centre_uv_ - Eigen::Vector2d(half, 0), t);
      }, &a) &&
      ProjectRollingShutter(k, row_time, cam, [&](double t) {
        return face_.WorldPoint(face_centre_uv_ + Eigen::Vector2d(half, 0), t);
      }, &b)) {
    tr.face_scale_px = (b - a).norm();
  }
  const double t_mid = RowTimeS(tr.stamp, 0.5 * (k.height - 1));
  tr.yaw = head_.Yaw(t_mid);
  tr.pitch = head_.Pitch(t_mid);
  const double t = ToSeconds(tr.stamp);
  const SimulatorOptions& o = options_;
  tr.occluded = Active(t, o.occlusion_start_s + 0.3 * (o.occlusion_end_s - o.occlusion_start_s),
                       o.occlusion_start_s + 0.7 * (o.occlusion_end_s - o.occlusion_start_s));
  tr.face_out = !tr.head_in_view;
  tr.second_face = Active(t, o.second_face_start_s, -1);
  tr.brightness_changed = Active(t, o.brightness_change_s, -1);
  return tr;
}

Status Simulator::Render(int i, cv::Mat* bgr, SimTruth* truth) const {
  if (i < 0 || i >= num_frames_) return Status::Error("sim: frame index out of range");
  *truth = Truth(i);
  RenderFrame(i, true, bgr);
  return Status::Ok();
}

std::vector<const Billboard*> Simulator::SubjectBoards() const {
  std::vector<const Billboard*> boards;
  if (options_.render_face && options_.render_torso) boards.push_back(&torso_);
  if (options_.render_face) boards.push_back(&face_);
  return boards;
}

Status Simulator::RenderTruthLayers(int i, cv::Mat* scene, cv::Mat* subject_alpha) const {
  if (i < 0 || i >= num_frames_) return Status::Error("sim: frame index out of range");
  RenderFrame(i, false, scene);
  const Time stamp = Stamp(i);
  RenderAlpha(intrinsics_, [&](double y) { return RowTimeS(stamp, y); },
              [this](double tt) { return CameraPose(tt); }, SubjectBoards(), options_.band_rows,
              subject_alpha);
  return Status::Ok();
}

void Simulator::RenderFrame(int i, bool with_subject, cv::Mat* bgr) const {
  const Time stamp = Stamp(i);
  const double t = ToSeconds(stamp);
  std::vector<const Billboard*> boards;
  if (Active(t, options_.passer_by_start_s, options_.passer_by_end_s)) {
    boards.push_back(&passer_by_);
  }
  if (Active(t, options_.second_face_start_s, -1)) boards.push_back(&second_face_);
  if (with_subject) {
    for (const Billboard* b : SubjectBoards()) boards.push_back(b);
  }
  if (Active(t, options_.occlusion_start_s, options_.occlusion_end_s)) {
    boards.push_back(&occluder_);
  }
  const int samples = options_.exposure_s > 0.0 ? std::max(1, options_.exposure_samples) : 1;
  if (samples == 1) {
    RenderScene(intrinsics_, [&](double y) { return RowTimeS(stamp, y); },
                [this](double tt) { return CameraPose(tt); }, *background_, boards,
                options_.band_rows, bgr);
  } else {
    // Motion blur: sub-frames spread evenly over each row's exposure,
    // centred on its row time, averaged.
    cv::Mat sum, sub;
    for (int k = 0; k < samples; ++k) {
      const double dt = options_.exposure_s * ((k + 0.5) / samples - 0.5);
      RenderScene(intrinsics_, [&](double y) { return RowTimeS(stamp, y) + dt; },
                  [this](double tt) { return CameraPose(tt); }, *background_, boards,
                  options_.band_rows, &sub);
      if (k == 0) {
        sub.convertTo(sum, CV_32FC3);
      } else {
        cv::accumulate(sub, sum);
      }
    }
    sum.convertTo(*bgr, CV_8UC3, 1.0 / samples);
  }
  if (options_.grayscale) {
    cv::Mat grey;
    cv::cvtColor(*bgr, grey, cv::COLOR_BGR2GRAY);
    cv::cvtColor(grey, *bgr, cv::COLOR_GRAY2BGR);
  }
  if (options_.brightness_change_s >= 0) {
    const double g = 1.0 + (options_.brightness_gain - 1.0) *
                               Ramp(t, options_.brightness_change_s,
                                    options_.brightness_change_s + 0.3);
    if (g != 1.0) bgr->convertTo(*bgr, -1, g, 0.0);
  }
}

bool Simulator::SubjectCovers(int i, const Eigen::Vector2d& px) const {
  if (!options_.render_face) return false;
  const double t = RowTimeS(Stamp(i), std::min(std::max(px.y(), 0.0), intrinsics_.height - 1.0));
  const Pose C = CameraPose(t);
  const CameraIntrinsics& k = intrinsics_;
  const Eigen::Vector3d ray =
      C.R * Eigen::Vector3d((px.x() - k.cx) / k.fx, (px.y() - k.cy) / k.fy, 1.0);
  auto covers = [&](const Billboard& b) {
    Eigen::Vector2d uv;
    if (!IntersectRelief(b, b.pose(t), C.p, ray, &uv)) return false;
    const int x = static_cast<int>(std::lround(uv.x())), y = static_cast<int>(std::lround(uv.y()));
    return b.bgra.at<cv::Vec4b>(y, x)[3] >= 128;
  };
  return covers(face_) || (options_.render_torso && covers(torso_));
}

bool Simulator::BackgroundPixel(int i, const Eigen::Vector3d& d, Eigen::Vector2d* px) const {
  const Time stamp = Stamp(i);
  const CameraIntrinsics& k = intrinsics_;
  double y = 0.5 * (k.height - 1);
  Eigen::Vector2d p;
  for (int it = 0; it < 10; ++it) {
    const Eigen::Vector3d c = CameraPose(RowTimeS(stamp, y)).R.conjugate() * d;
    if (c.z() <= 1e-9) return false;
    p = Eigen::Vector2d(k.fx * c.x() / c.z() + k.cx, k.fy * c.y() / c.z() + k.cy);
    y = std::min(std::max(p.y(), 0.0), k.height - 1.0);
  }
  *px = p;
  return true;
}

}  // namespace sim
}  // namespace steadiface
