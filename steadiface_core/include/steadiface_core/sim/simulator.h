#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/sim/head_relief.h"
#include "steadiface_core/sim/motion.h"
#include "steadiface_core/sim/scene_renderer.h"
#include "steadiface_core/view/gravity.h"

namespace steadiface {
namespace sim {

/// Everything that defines a simulated selfie sequence. ApplyPreset() fills
/// it for the named presets; every field can be overridden afterwards.
struct SimulatorOptions {
  /// Image size [px], frame rate [Hz], duration [s], horizontal FOV [rad].
  int width = 640, height = 360;
  double fps = 30.0;
  double duration_s = 3.0;
  double hfov_rad = 1.1;
  /// Rolling-shutter readout [s]; frames are stamped at the first row.
  double readout_s = 0.02;
  /// Rows per rendered band (each band is rendered with its own pose).
  int band_rows = 8;
  /// Exposure time [s]: each row integrates the scene over
  /// [row time - exposure/2, row time + exposure/2], rendered as
  /// exposure_samples sub-frames averaged (motion blur). 0: instantaneous.
  double exposure_s = 0.0;
  int exposure_samples = 6;
  /// Render grey (the BGR frame's three channels equal: a monochrome
  /// sensor's picture, a grayscale portrait).
  bool grayscale = false;
  uint64_t seed = 1;
  /// Data folder with astronaut.png, building.jpg and gyro/ (test/data).
  std::string data_dir;
  std::string face_photo = "astronaut.png";
  std::string background_photo = "building.jpg";
  /// The background photo's contrast about its mean [-] and a Gaussian blur
  /// of it [px, sigma]: 1 and 0 show it as it is; a small contrast and a
  /// blur make a plain, low-texture wall.
  double background_contrast = 1.0;
  double background_blur_px = 0.0;
  /// Head region cropped from the face photo onto the billboard, the
  /// landmark centre inside the photo and the face width there [px]
  /// (defaults: astronaut.png, from dlib's 68 landmarks).
  cv::Rect face_region = cv::Rect(139, 38, 168, 188);
  Eigen::Vector2d face_centre_px = Eigen::Vector2d(224.1, 127.4);
  double face_width_px = 88.0;
  /// The photo's 68 landmarks (data_dir/face_landmarks: one "x y" per line,
  /// photo px; for astronaut.png, dlib's 68-point predictor's), which give
  /// the relief its mean face (HeadReliefOptions::mean_face); "": none.
  std::string face_landmarks = "astronaut_landmarks68.txt";
  /// Camera motion: parametric (pan + band-limited shake + translation) ...
  CameraMotionOptions camera;
  /// ... or the real recorded gyro trace (data_dir/gyro), scaled by
  /// real_gyro_scale, replacing the parametric rotation. Sequences longer
  /// than the 9.9 s trace play it forwards, then backwards.
  bool use_real_gyro = false;
  /// The pan turns the person too: camera and head orbit the head's base
  /// position together (a vlogger turning with the phone at arm's length),
  /// so the face stays in view while the background pans.
  bool pan_orbits_head = true;
  double real_gyro_scale = 1.0;
  /// Playback speed of the real trace [-]: 2 plays it twice as fast, which
  /// doubles the angular velocity (blur, rolling-shutter skew) and the
  /// frequencies but keeps the rotation's amplitude (what the crop must
  /// absorb); real_gyro_scale scales both velocity and amplitude.
  double real_gyro_speed = 1.0;
  /// Head motion relative to the body, and the body's walking motion shared
  /// by camera and head [m, Hz].
  HeadMotionOptions head;
  double body_bob_m = 0.02, body_sway_m = 0.01, body_bob_hz = 1.8;
  /// Render the face at all (false: background only, e.g. a robot camera).
  bool render_face = true;
  /// Render neck and shoulders under the face, moving with the head's
  /// position (not its turning or nodding), torso_depth_m behind the face
  /// plane [m]; shoulders torso_width_m wide [m].
  bool render_torso = false;
  double torso_depth_m = 0.04;
  double torso_width_m = 0.42;
  /// Face width on the billboard [m].
  double face_width_m = 0.15;
  /// The face's shape: "relief" (a head: the photo on an ellipsoid with a
  /// nose, turning about the skull's centre behind the face, so that its
  /// landmarks move and hide as a real head's do when it turns) or "flat"
  /// (the photo on a plane turning about its centre, as before 2026-11-26).
  std::string head_model = "relief";
  /// The relief's shape, with head_model "relief".
  HeadReliefOptions relief;
  /// Hair at the head's top edge: the upper part of the face billboard's
  /// outline becomes strands of varying length, semi-transparent between
  /// them (a soft, ragged edge like real hair).
  bool hair_edge = false;
  /// A passer-by (a person 2.5 m away, walking across the view behind the
  /// subject) between these times [s]; negative = never. Part of the scene,
  /// not of the subject.
  double passer_by_start_s = -1, passer_by_end_s = -1;
  /// IMU: gyro rate [Hz], white noise [rad/s], constant bias [rad/s],
  /// timestamp jitter (std) [s], clock offset: IMU stamps are true time
  /// minus this, so the stabilizer's imu_time_offset must be +this [s].
  double imu_rate_hz = 200.0;
  double gyro_noise = 0.002;
  Eigen::Vector3d gyro_bias = Eigen::Vector3d(0.001, -0.0015, 0.0005);
  double imu_jitter_s = 0.0002;
  /// Accelerometer white noise [m/s^2] (the readings: the specific force,
  /// gravity along the world's +y, "down", and the camera's acceleration).
  double accel_noise = 0.03;
  double imu_clock_offset_s = 0.0;
  /// The IMU drops out: no gyro or accelerometer sample between these
  /// times [s] (a cable or driver fault); negative = never.
  double imu_dropout_start_s = -1, imu_dropout_end_s = -1;
  /// Events (times in seconds from the start; negative = never).
  double occlusion_start_s = -1, occlusion_end_s = -1;
  double face_out_start_s = -1, face_out_end_s = -1;
  double second_face_start_s = -1;
  /// The second face grows (walks closer) from 1.2 m to this distance [m].
  double second_face_final_distance_m = 1.2;
  double brightness_change_s = -1;
  double brightness_gain = 1.6;
};

/// Presets: still, walk, pan, run, occlusion, two_faces, turn_away, vlog
/// (a walking selfie at arm's length, 0.7 m, with head and shoulders in
/// front of a building: what the layered warp is judged on), shake (the
/// recorded running trace at 3x, grey, 25 ms exposure blur, 30 ms
/// readout: what the face tracker is judged on under strong shake), drift,
/// walk_across, bob (a walking selfie whose head bobs against the scene by
/// +-100 px at 720p, with neck and shoulders: what the composite is judged
/// on), hair (vlog with hair strands at the head's top edge), passer_by
/// (walk with neck and shoulders, a person walking across behind), roll
/// (walk under a slow +-10 deg roll: what the level horizon is judged on),
/// low_texture (walk in front of a pale wall: 20 % of the building's
/// contrast, softened), dropout (walk, at least 7 s long, whose IMU drops out
/// from 3 s to 5 s): the last two judge the rotation from the video.
Status ApplyPreset(const std::string& name, SimulatorOptions* options);
const std::vector<std::string>& PresetNames();

/// Ground truth of one frame.
struct SimTruth {
  Time stamp;  ///< first-row capture time
  /// True real rotation (world -> camera) at `rotation_rows` rows.
  std::vector<double> rotation_rows;
  std::vector<Eigen::Quaterniond> R_r;
  /// True head centre in the image [px], projected at its own row, and
  /// whether it is in view: where the face photo's landmark centre would be
  /// if the head faced forward. It moves with the head, not with the head's
  /// turning and nodding (the paper's pose-invariant head: a stabilizer
  /// should not follow a head that only turns).
  Eigen::Vector2d head_px = Eigen::Vector2d::Zero();
  bool head_in_view = false;
  /// The landmark centre as the turned face shows it [px] (on a flat face
  /// nearly head_px; on a relief it moves sideways as the head turns).
  Eigen::Vector2d face_px = Eigen::Vector2d::Zero();
  /// The head's true yaw and pitch against its forward pose [rad].
  double yaw = 0.0, pitch = 0.0;
  /// Face width in the image [px].
  double face_scale_px = 0.0;
  /// Events active in this frame.
  bool occluded = false, face_out = false, second_face = false,
       brightness_changed = false;
};

/// Renders frames and IMU with exact ground truth (issue: simulator).
/// Deterministic: the same options give byte-identical frames, IMU and
/// truth.
class Simulator {
 public:
  static Status Create(const SimulatorOptions& options,
                       std::unique_ptr<Simulator>* out);

  int num_frames() const { return num_frames_; }
  /// Length of the recorded gyro trace a real-gyro preset (run) replays [s];
  /// 0 without one. Longer sequences play it forwards, then backwards.
  double real_gyro_span_s() const { return real_gyro_span_s_; }
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  const RowTiming& timing() const { return timing_; }
  /// Gyro samples as the IMU reports them (camera axes, IMU clock).
  const std::vector<GyroSample>& imu() const { return imu_; }
  /// Accelerometer readings at the gyro's stamps (camera axes, IMU clock).
  const std::vector<AccelSample>& accel() const { return accel_; }
  /// Gravity's "up" in the camera at time t [s] (the world is level: up is
  /// its -y).
  Eigen::Vector3d UpInCamera(double t) const;
  const SimulatorOptions& options() const { return options_; }

  /// Renders frame i (BGR) and its truth.
  Status Render(int i, cv::Mat* bgr, SimTruth* truth) const;
  /// Truth only (fast).
  SimTruth Truth(int i) const;
  /// The truth behind the composite: frame i as Render makes it without the
  /// subject (face and torso; the scene, passers-by and the hand stay), and
  /// the subject's true coverage (CV_8UC1, 255 = the subject alone).
  Status RenderTruthLayers(int i, cv::Mat* scene, cv::Mat* subject_alpha) const;

  /// True camera-to-world pose at time t [s].
  Pose CameraPose(double t) const;
  /// True when the subject (face or torso billboard, alpha >= 0.5) covers
  /// input pixel `px` of frame i (the pose at the pixel's row).
  bool SubjectCovers(int i, const Eigen::Vector2d& px) const;
  /// Where a world direction at infinity appears in frame i [px], at its
  /// own row. False when behind the camera.
  bool BackgroundPixel(int i, const Eigen::Vector3d& direction,
                       Eigen::Vector2d* px) const;

 private:
  explicit Simulator(const SimulatorOptions& options);
  Status Init();
  // Init's pieces: the face's relief (head_model "relief"); the torso
  // billboard; the second face and the occluder; the recorded gyro trace
  // (use_real_gyro); the IMU samples.
  Status MakeRelief(double m_per_px);
  void MakeTorso();
  void MakeSecondFaceAndOccluder(const cv::Mat& photo, double m_per_px);
  Status LoadRealGyro();
  void SynthesizeImu();
  // Frame i, with or without the subject.
  void RenderFrame(int i, bool with_subject, cv::Mat* bgr) const;
  std::vector<const Billboard*> SubjectBoards() const;
  Eigen::Vector3d Body(double t) const;
  /// The face billboard's pose at t, turned by the head's yaw and pitch
  /// about the head's turning centre (relief: the skull's centre), or as if
  /// the head faced forward (turned = false).
  Pose FacePose(double t, bool turned) const;
  /// Applies the pan orbit (if any) to a world pose.
  Pose Orbit(const Pose& P, double t) const;
  double RowTimeS(Time stamp, double y) const;
  Time Stamp(int i) const;

  SimulatorOptions options_;
  CameraIntrinsics intrinsics_;
  RowTiming timing_;
  int num_frames_ = 0;
  CameraMotion camera_;
  HeadMotion head_;
  std::unique_ptr<OrientationTimeline> real_gyro_;  // when use_real_gyro
  double real_gyro_span_s_ = 0.0;
  /// Time in the real trace for sequence time t (mirrored past its end).
  double RealGyroTime(double t, double* sign) const;
  std::unique_ptr<InfiniteBackground> background_;
  Billboard face_, second_face_, occluder_, torso_, passer_by_;
  // hair_edge: the face billboard's top edge as strands.
  void MakeHair();
  void MakePasserBy();
  Eigen::Vector2d face_centre_uv_ = Eigen::Vector2d::Zero();
  // The same centre in the face billboard's frame, on its plane [m].
  Eigen::Vector3d face_front_ = Eigen::Vector3d::Zero();
  // The head's turning centre in the face billboard's frame [m] (zero: the
  // billboard's anchor, the flat face).
  Eigen::Vector3d turning_centre_ = Eigen::Vector3d::Zero();
  std::vector<GyroSample> imu_;
  std::vector<AccelSample> accel_;
};

/// Loads a deepfvs gyro log ("t_us gx gy gz ...") as camera-frame samples
/// (omega_cam = (g_y, g_x, -g_z)), with times relative to the first sample.
Status LoadDeepFvsGyro(const std::string& path, std::vector<GyroSample>* out);

}  // namespace sim
}  // namespace steadiface
