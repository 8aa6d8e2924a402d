#include "steadiface_ros/msg_conversion.h"

#include <cmath>
#include <sstream>

#include <cstring>

#include <opencv2/imgproc.hpp>
#include <sensor_msgs/image_encodings.h>

#include "image_decoder.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/face/landmarks68.h"
#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {

steadiface::Status ToCameraIntrinsics(const sensor_msgs::CameraInfo& info,
                                      steadiface::CameraIntrinsics* out) {
  using steadiface::DistortionModel;
  using steadiface::Status;
  std::ostringstream err;
  if (info.K[0] == 0.0 && info.K[4] == 0.0) {
    return Status::Error(
        "camera_info: K is all zero (uncalibrated camera); calibrate it or "
        "publish a camera_info with fx, fy, cx, cy");
  }
  steadiface::CameraIntrinsics k;
  const int bx = info.binning_x > 1 ? static_cast<int>(info.binning_x) : 1;
  const int by = info.binning_y > 1 ? static_cast<int>(info.binning_y) : 1;
  const bool roi = info.roi.width > 0 && info.roi.height > 0 &&
                   (info.roi.width != info.width ||
                    info.roi.height != info.height);
  const double full_w = roi ? info.roi.width : info.width;
  const double full_h = roi ? info.roi.height : info.height;
  const double ox = roi ? info.roi.x_offset : 0.0;
  const double oy = roi ? info.roi.y_offset : 0.0;
  k.width = static_cast<int>(full_w) / bx;
  k.height = static_cast<int>(full_h) / by;
  k.fx = info.K[0] / bx;
  k.fy = info.K[4] / by;
  k.cx = (info.K[2] - ox) / bx;
  k.cy = (info.K[5] - oy) / by;

  const std::string& model = info.distortion_model;
  bool all_zero = true;
  for (double d : info.D) all_zero = all_zero && d == 0.0;
  if (info.D.empty() || all_zero) {
    k.distortion = DistortionModel::kNone;
  } else if (model == "plumb_bob" || model == "rational_polynomial") {
    k.distortion = DistortionModel::kPlumbBob;
    k.distortion_coeffs = info.D;
  } else if (model == "equidistant" || model == "fisheye") {
    k.distortion = DistortionModel::kEquidistant;
    k.distortion_coeffs = info.D;
  } else {
    err << "camera_info: unsupported distortion_model '" << model
        << "' with non-zero D (supported: plumb_bob, rational_polynomial, "
           "equidistant)";
    return Status::Error(err.str());
  }
  Status s = steadiface::ValidateIntrinsics(k);
  if (!s.ok()) return s;
  *out = k;
  return Status::Ok();
}

steadiface::GyroSample ToGyroSample(const sensor_msgs::Imu& imu) {
  steadiface::GyroSample s;
  s.stamp = ToCoreTime(imu.header.stamp);
  s.angular_velocity = Eigen::Vector3d(
      imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z);
  return s;
}

bool ToAccelSample(const sensor_msgs::Imu& imu, steadiface::AccelSample* out) {
  const auto& a = imu.linear_acceleration;
  if (imu.linear_acceleration_covariance[0] == -1.0 || (a.x == 0.0 && a.y == 0.0 && a.z == 0.0)) {
    return false;
  }
  out->stamp = ToCoreTime(imu.header.stamp);
  out->linear_acceleration = Eigen::Vector3d(a.x, a.y, a.z);
  return true;
}

bool ToEigen(const geometry_msgs::Quaternion& msg, Eigen::Quaterniond* q) {
  Eigen::Quaterniond e(msg.w, msg.x, msg.y, msg.z);
  const double n = e.norm();
  if (!std::isfinite(n) || n < 1e-9) return false;
  *q = Eigen::Quaterniond(e.coeffs() / n);
  return true;
}

geometry_msgs::Quaternion ToMsg(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion m;
  m.w = q.w();
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  return m;
}

geometry_msgs::Transform ToTransformMsg(const Eigen::Quaterniond& q) {
  geometry_msgs::Transform t;
  t.rotation = ToMsg(q);
  return t;
}

namespace {

// Pixel layout of an encoding: what image_encodings knows, plus the YUYV
// names that Debian 12's image_encodings lacks. False for an unknown name.
bool PixelLayout(const std::string& e, int* channels, int* depth) {
  if (e == "yuyv" || e == "yuv422_yuy2" || e == "uyvy") {
    *channels = 2;
    *depth = 8;
    return true;
  }
  try {
    *channels = sensor_msgs::image_encodings::numChannels(e);
    *depth = sensor_msgs::image_encodings::bitDepth(e);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

// ROS bayer pattern (its top-left 2x2) -> OpenCV's demosaicing code (OpenCV
// names the pattern by the second row's second and third pixels).
int BayerToBgrCode(const std::string& e) {
  namespace enc = sensor_msgs::image_encodings;
  if (e == enc::BAYER_RGGB8 || e == enc::BAYER_RGGB16) return cv::COLOR_BayerBG2BGR;
  if (e == enc::BAYER_BGGR8 || e == enc::BAYER_BGGR16) return cv::COLOR_BayerRG2BGR;
  if (e == enc::BAYER_GBRG8 || e == enc::BAYER_GBRG16) return cv::COLOR_BayerGR2BGR;
  return cv::COLOR_BayerGB2BGR;  // GRBG
}

// The message's size, encoding, step and data checked; its pixel layout
// into *channels and *depth. Float and signed images are refused.
steadiface::Status CheckImageLayout(const sensor_msgs::Image& msg, int* channels_out,
                                    int* depth_out) {
  using steadiface::Status;
  if (msg.width == 0 || msg.height == 0) {
    return Status::Error("image: zero size (" + std::to_string(msg.width) + "x" +
                         std::to_string(msg.height) + ")");
  }
  if (msg.width > 16384 || msg.height > 16384) {
    return Status::Error("image: implausible size " + std::to_string(msg.width) + "x" +
                         std::to_string(msg.height));
  }
  int channels = 0, depth = 0;
  if (!PixelLayout(msg.encoding, &channels, &depth)) {
    return Status::Error("image: unknown encoding '" + msg.encoding + "'");
  }
  const uint64_t min_step = static_cast<uint64_t>(msg.width) * channels * (depth / 8);
  if (min_step == 0 || msg.step < min_step) {
    return Status::Error("image: step " + std::to_string(msg.step) + " is smaller than width * pixel size " +
                         std::to_string(min_step));
  }
  if (static_cast<uint64_t>(msg.step) * msg.height != msg.data.size()) {
    return Status::Error("image: data has " + std::to_string(msg.data.size()) + " bytes, step * height is " +
                         std::to_string(static_cast<uint64_t>(msg.step) * msg.height));
  }
  const std::string& e = msg.encoding;
  // Float and signed images are depth maps or processed data, not a
  // camera's picture: refuse them rather than stabilize a false rendering.
  if (e.find("32F") != std::string::npos || e.find("64F") != std::string::npos ||
      e.find("8S") != std::string::npos || e.find("16S") != std::string::npos ||
      e.find("32S") != std::string::npos) {
    return Status::Error("image: encoding '" + e +
                         "' is a float or signed image (a depth map?), not a camera picture; "
                         "supported: mono8/16, bgr8, rgb8, bgra8, rgba8, yuv422 (UYVY), "
                         "yuyv/yuv422_yuy2, bayer_*8/16, and compressed via image_transport");
  }
  const bool bigendian_mismatch = depth > 8 && msg.is_bigendian;
  if (bigendian_mismatch) {
    return Status::Error("image: big-endian " + e + " is not supported (is_bigendian set)");
  }
  *channels_out = channels;
  *depth_out = depth;
  return Status::Ok();
}

// Bayer (8 or 16 bits) demosaiced to BGR8; the colour is there, so not to grey.
steadiface::Status ConvertBayer(const sensor_msgs::Image& msg, int depth, uint8_t* data,
                                cv::Mat* image) {
  using steadiface::Status;
  if (msg.width < 2 || msg.height < 2) return Status::Error("image: bayer image below 2x2");
  const cv::Mat src(msg.height, msg.width, depth == 16 ? CV_16UC1 : CV_8UC1, data, msg.step);
  cv::Mat bgr;
  cv::cvtColor(src, bgr, BayerToBgrCode(msg.encoding));
  if (depth == 16) {
    bgr.convertTo(*image, CV_8U, 255.0 / 65535.0);
  } else {
    *image = bgr;
  }
  return Status::Ok();
}

// mono16, 16UC1, bgr16, rgb16, ...: the full 16-bit range to 8 bits, BGR order.
void Convert16(const sensor_msgs::Image& msg, int channels, uint8_t* data, cv::Mat* image) {
  namespace enc = sensor_msgs::image_encodings;
  const std::string& e = msg.encoding;
  const cv::Mat src(msg.height, msg.width, CV_MAKETYPE(CV_16U, channels), data, msg.step);
  cv::Mat scaled;
  src.convertTo(scaled, CV_8U, 255.0 / 65535.0);
  if (channels == 1) {
    *image = scaled;
  } else if (e == enc::RGB16 || e == enc::RGBA16) {
    cv::cvtColor(scaled, *image, channels == 3 ? cv::COLOR_RGB2BGR : cv::COLOR_RGBA2BGR);
  } else if (channels == 3) {
    *image = scaled;
  } else {
    cv::cvtColor(scaled, *image, cv::COLOR_BGRA2BGR);
  }
}

}  // namespace

steadiface::Status ToCvImage(const sensor_msgs::Image& msg, cv::Mat* image) {
  using steadiface::Status;
  namespace enc = sensor_msgs::image_encodings;
  int channels = 0, depth = 0;
  const Status layout = CheckImageLayout(msg, &channels, &depth);
  if (!layout.ok()) return layout;
  const std::string& e = msg.encoding;
  uint8_t* data = const_cast<uint8_t*>(msg.data.data());  // never written to
  if (e == enc::MONO8 || e == enc::BGR8 || e == enc::BGRA8 || e == enc::TYPE_8UC1 ||
      e == enc::TYPE_8UC3 || e == enc::TYPE_8UC4) {
    // Wraps the message's memory.
    *image = cv::Mat(msg.height, msg.width, CV_MAKETYPE(CV_8U, channels), data, msg.step);
    return Status::Ok();
  }
  try {
    if (e == enc::RGB8 || e == enc::RGBA8) {
      const cv::Mat src(msg.height, msg.width, CV_MAKETYPE(CV_8U, channels), data, msg.step);
      cv::cvtColor(src, *image, e == enc::RGB8 ? cv::COLOR_RGB2BGR : cv::COLOR_RGBA2BGR);
      return Status::Ok();
    }
    if (channels == 2 && depth == 8 &&
        (e == enc::YUV422 || e == "uyvy" || e == "yuyv" || e == "yuv422_yuy2")) {
      // USB cameras: 4:2:2, two pixels share U and V. yuv422 is UYVY.
      if (msg.width % 2 != 0) return Status::Error("image: " + e + " needs an even width");
      const cv::Mat src(msg.height, msg.width, CV_8UC2, data, msg.step);
      const bool uyvy = e == enc::YUV422 || e == "uyvy";
      cv::cvtColor(src, *image, uyvy ? cv::COLOR_YUV2BGR_UYVY : cv::COLOR_YUV2BGR_YUYV);
      return Status::Ok();
    }
    if (enc::isBayer(e)) return ConvertBayer(msg, depth, data, image);
    if (depth == 16 && (channels == 1 || channels == 3 || channels == 4)) {
      Convert16(msg, channels, data, image);
      return Status::Ok();
    }
    // What is left (8UC2, 16UC2: two channels that are not a named 4:2:2
    // layout) has no picture to make; cv_bridge refuses them too.
    return Status::Error("image: unsupported encoding '" + e +
                         "' (two channels, not a YUV 4:2:2 layout); supported: mono8/16, "
                         "bgr8, rgb8, bgra8, rgba8, yuv422 (UYVY), yuyv/yuv422_yuy2, "
                         "bayer_*8/16, and compressed via image_transport");
  } catch (const cv::Exception& ex) {
    return Status::Error("image: conversion of '" + e + "' failed: " + ex.what());
  }
}

sensor_msgs::ImagePtr ToImageMsg(const std_msgs::Header& header, const std::string& encoding,
                                 const cv::Mat& image) {
  sensor_msgs::ImagePtr msg(new sensor_msgs::Image);
  msg->header = header;
  msg->height = static_cast<uint32_t>(image.rows);
  msg->width = static_cast<uint32_t>(image.cols);
  msg->encoding = encoding;
  msg->is_bigendian = 0;  // OpenCV's pixels are in the host's order
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  msg->is_bigendian = 1;
#endif
  const size_t row = static_cast<size_t>(image.cols) * image.elemSize();
  msg->step = static_cast<uint32_t>(row);
  msg->data.resize(row * static_cast<size_t>(image.rows));
  if (image.isContinuous()) {
    if (!msg->data.empty()) std::memcpy(msg->data.data(), image.data, msg->data.size());
  } else {
    for (int r = 0; r < image.rows; ++r) {
      std::memcpy(msg->data.data() + row * static_cast<size_t>(r), image.ptr(r), row);
    }
  }
  return msg;
}

steadiface::Status FromCompressedImage(const sensor_msgs::CompressedImage& msg,
                                       sensor_msgs::ImagePtr* out) {
  using steadiface::Status;
  const std::string& f = msg.format;
  if (f.find("compressedDepth") != std::string::npos) {
    return Status::Error("compressed image: format '" + f +
                         "' is a compressed depth map, not a camera picture");
  }
  const bool jpeg = f.find("jpeg") != std::string::npos || f.find("jpg") != std::string::npos;
  const bool png = f.find("png") != std::string::npos;
  if (!jpeg && !png) {
    return Status::Error("compressed image: format '" + f + "' is neither jpeg nor png");
  }
  if (msg.data.empty()) return Status::Error("compressed image: no data");
  cv::Mat decoded;
  std::string why;
  if (!DecodeImage(msg.data.data(), msg.data.size(), &decoded, &why)) {
    return Status::Error("compressed image: cannot decode the " + std::string(jpeg ? "jpeg" : "png") +
                         " payload (" + std::to_string(msg.data.size()) + " bytes): " + why);
  }
  if (decoded.cols > 16384 || decoded.rows > 16384) {
    return Status::Error("compressed image: implausible size " + std::to_string(decoded.cols) +
                         "x" + std::to_string(decoded.rows));
  }
  namespace enc = sensor_msgs::image_encodings;
  std::string encoding;
  if (decoded.depth() == CV_16U) {
    encoding = decoded.channels() == 1 ? enc::MONO16 : decoded.channels() == 3 ? enc::BGR16 : enc::BGRA16;
  } else if (decoded.depth() == CV_8U) {
    encoding = decoded.channels() == 1 ? enc::MONO8 : decoded.channels() == 3 ? enc::BGR8 : enc::BGRA8;
  } else {
    return Status::Error("compressed image: decoded to an unsupported pixel type");
  }
  // The decoder gives BGR; a "rgb8; jpeg compressed bgr8" producer encoded
  // BGR too (compressed_image_transport converts before encoding).
  *out = ToImageMsg(msg.header, encoding, decoded);
  return Status::Ok();
}

sensor_msgs::CameraInfo ToCameraInfo(const steadiface::CameraIntrinsics& k,
                                     const std_msgs::Header& header) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = k.width;
  info.height = k.height;
  info.distortion_model = "plumb_bob";
  info.D = {0.0, 0.0, 0.0, 0.0, 0.0};
  info.K = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

steadiface::FaceLandmarks ToMsg(const steadiface::FaceInfo& f, const std_msgs::Header& header) {
  steadiface::FaceLandmarks m;
  m.header = header;
  m.state = f.state == steadiface::TrackingState::kTracking
                ? steadiface::FaceLandmarks::TRACKING
                : f.state == steadiface::TrackingState::kLost ? steadiface::FaceLandmarks::LOST
                                                              : steadiface::FaceLandmarks::SEARCHING;
  m.failure = steadiface::FaceFailureName(f.failure);
  m.valid = f.valid;
  m.followed = f.followed;
  m.confidence = static_cast<float>(f.confidence);
  m.box_x = static_cast<float>(f.box.x);
  m.box_y = static_cast<float>(f.box.y);
  m.box_width = static_cast<float>(f.box.width);
  m.box_height = static_cast<float>(f.box.height);
  for (const auto& p : f.landmarks_px) {
    geometry_msgs::Point q;
    q.x = p.x();
    q.y = p.y();
    m.points.push_back(q);
  }
  m.centre.x = f.centre_px.x();
  m.centre.y = f.centre_px.y();
  m.scale = static_cast<float>(f.scale_px);
  m.has_pose = f.has_pose;
  m.yaw = static_cast<float>(f.yaw);
  m.pitch = static_cast<float>(f.pitch);
  m.roll = static_cast<float>(f.roll);
  return m;
}

steadiface::Status FromMsg(const steadiface::FaceLandmarks& m, std::vector<Eigen::Vector2d>* points,
                           double* confidence) {
  points->clear();
  *confidence = std::isfinite(m.confidence) ? std::min(1.0f, std::max(0.0f, m.confidence)) : 0.0;
  if (!m.valid) return steadiface::Status::Ok();
  if (m.points.size() != steadiface::landmarks68::kCount) {
    return steadiface::Status::Error("landmarks_in: need 68 points, got " +
                                     std::to_string(m.points.size()));
  }
  for (const auto& p : m.points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      points->clear();
      return steadiface::Status::Error("landmarks_in: non-finite point");
    }
    points->emplace_back(p.x, p.y);
  }
  return steadiface::Status::Ok();
}

namespace {

// StabilizerState from a PipelineFrame, in parts: the terms' energies and
// weights, the weight factors and the solver; the face checks and the
// stabilizer's flags; both layers and the blend; the gyro-vs-video check;
// and nothing non-finite leaving the node.
void FillTermsAndSolver(const steadiface::StabilizerFrame& f, steadiface::StabilizerState* out) {
  steadiface::StabilizerState& m = *out;
  m.energy_fit = f.energies.fit;
  m.energy_distortion = f.energies.distortion;
  m.energy_follow = f.energies.follow;
  m.energy_rotation = f.energies.rotation;
  m.energy_translation = f.energies.translation;
  m.energy_protrusion = f.energies.protrusion;
  m.w_fit = f.weights.fit;
  m.w_distortion = f.weights.distortion;
  m.w_follow = f.weights.follow;
  m.w_rotation_c0 = f.weights.rotation_c0;
  m.w_rotation_c1 = f.weights.rotation_c1;
  m.w_translation_c0 = f.weights.translation_c0;
  m.w_translation_c1 = f.weights.translation_c1;
  m.w_protrusion = f.weights.protrusion;
  m.fit_factor = f.factors.fit;
  m.smoothness_factor = f.factors.smoothness;
  m.mean_angular_speed = f.factors.mean_angular_speed;
  m.solver_iterations = static_cast<uint32_t>(std::max(0, f.solver.iterations));
  m.solver_termination = f.solver.termination;
  m.solver_time_ms = f.solver.time_ms;
  m.solver_usable = f.solver.usable;
}

void FillFaceAndFlags(const steadiface::PipelineFrame& pf, steadiface::StabilizerState* out) {
  const steadiface::StabilizerFrame& f = pf.stabilizer;
  steadiface::StabilizerState& m = *out;
  m.face_state = static_cast<uint8_t>(pf.face.state);
  m.face_failure = steadiface::FaceFailureName(pf.face.failure);
  m.face_detected = pf.face.detected;
  m.face_shape_residual = pf.face.shape_residual;
  m.face_spread_ratio = pf.face.spread_ratio;
  m.face_jump = pf.face.jump;
  m.face_appearance = pf.face.appearance;
  m.face_used = f.flags.face_used;
  m.held_face = f.flags.held_face;
  m.solver_failed = f.flags.solver_failed;
  m.protrusion_search = f.flags.protrusion_search;
  m.protrusion_search_s = f.flags.protrusion_search_s;
  m.previous_warp = f.flags.previous_warp;
  m.undefined_pixels = f.flags.undefined_pixels;
}

void FillLayers(const steadiface::PipelineFrame& pf, steadiface::StabilizerState* out) {
  const steadiface::StabilizerFrame& f = pf.stabilizer;
  steadiface::StabilizerState& m = *out;
  m.has_background_layer = f.background.valid;
  m.background_rotation = ToMsg(f.background.R_v);
  m.background_principal_offset = {f.background.t.x(), f.background.t.y()};
  m.warp_mode = pf.layered.active ? "layered" : pf.composite.active ? "composite" : "global";
  m.crop_mode = pf.crop.dynamic ? "dynamic" : "fixed";
  m.crop_ratio = pf.crop.crop_ratio;
  m.crop_target = pf.crop.target;
  m.crop_shake_need = pf.crop.shake_need;
  m.crop_solved_need = pf.crop.solved_need;
  if (pf.composite.active) {
    const steadiface::CompositeReport& c = pf.composite.report;
    m.layer_blend = pf.composite.region.blend;
    m.layer_blend_step = pf.composite.region.blend_step;
    m.matte_mean = c.matte_mean;
    m.uncovered_px = c.uncovered_px;
    m.plate_share = c.plate_share;
    m.fallback_share = c.fallback_share;
    m.plate_coverage = c.plate_coverage;
    m.plate_restarts = static_cast<uint32_t>(std::max(0, c.plate_restarts));
  }
  if (pf.layered.active) {
    const steadiface::LayerBlendReport& b = pf.layered.blend;
    m.layer_blend = pf.layered.region.blend;
    m.layer_blend_step = pf.layered.region.blend_step;
    m.band_px = b.band_px;
    m.layer_offset_px = b.offset_px;
    m.layer_offset_capped_px = b.capped_offset_px;
    m.layer_shift_px = b.shift_px;
    m.layer_keep = b.protrusion_keep * b.distortion_keep;
    m.min_cell_ratio = b.min_cell_ratio;
    m.folded_cells = static_cast<uint32_t>(std::max(0, b.folded_cells));
  } else {
    m.layer_keep = 1.0;
    m.min_cell_ratio = 1.0;
  }
}

void FillGyroVideoCheck(const steadiface::PipelineFrame& pf, steadiface::StabilizerState* out) {
  steadiface::StabilizerState& m = *out;
  const steadiface::GyroVideoCheckResult& c = pf.gyro_video_check;
  m.check_judged = c.judged;
  m.check_motion_px = c.motion_px;
  m.check_residual_px = c.residual_configured_px;
  m.check_best_mounting_residual_px = c.residual_best_mounting_px;
  m.imu_rotation_contradicts = c.rotation_contradicts;
  m.suggested_R_cam_imu = ToMsg(c.best_R_cam_imu);
  m.imu_offset_correction_s = c.offset_correction_s;
  m.imu_offset_off = c.offset_off;
  m.imu_offset_applied_s = pf.imu_offset_applied_s;
  m.rotation_source = pf.rotation_from_video ? "visual" : "imu";
  if (pf.rotation_from_video) {
    m.visual_valid = pf.visual.valid;
    m.visual_tracked = static_cast<uint32_t>(std::max(0, pf.visual.tracked));
    m.visual_inliers = static_cast<uint32_t>(std::max(0, pf.visual.inliers));
    m.visual_residual_px = pf.visual.residual_px;
    m.visual_turn_error_px = pf.visual.turn_error_px;
  }
}

void ZeroNonFinite(steadiface::StabilizerState* out) {
  steadiface::StabilizerState& m = *out;
  // Nothing non-finite leaves the node.
  auto clean = [](double& v) {
    if (!std::isfinite(v)) v = 0.0;
  };
  for (double* v : {&m.energy_fit, &m.energy_distortion, &m.energy_follow, &m.energy_rotation,
                    &m.energy_translation, &m.energy_protrusion, &m.mean_angular_speed,
                    &m.face_shape_residual, &m.face_spread_ratio, &m.face_jump,
                    &m.face_appearance, &m.imu_offset_applied_s, &m.visual_residual_px,
                    &m.visual_turn_error_px, &m.layer_blend, &m.layer_blend_step, &m.band_px,
                    &m.layer_offset_px, &m.layer_offset_capped_px, &m.layer_shift_px, &m.layer_keep,
                    &m.min_cell_ratio, &m.matte_mean, &m.uncovered_px, &m.plate_share,
                    &m.fallback_share, &m.plate_coverage}) {
    clean(*v);
  }
}

}  // namespace

steadiface::StabilizerState ToMsg(const steadiface::PipelineFrame& pf, const std_msgs::Header& header,
                                  bool gyro_extrapolated) {
  const steadiface::StabilizerFrame& f = pf.stabilizer;
  steadiface::StabilizerState m;
  m.header = header;
  m.has_target = f.has_target;
  m.target_h = {f.H.x(), f.H.y()};
  m.centre_c = {f.C.x(), f.C.y()};
  m.virtual_rotation = ToMsg(f.R_v);
  m.real_rotation = ToMsg(f.R_r);
  m.principal_offset = {f.t.x(), f.t.y()};
  FillTermsAndSolver(f, &m);
  FillFaceAndFlags(pf, &m);
  m.gyro_extrapolated = gyro_extrapolated;
  FillLayers(pf, &m);
  FillGyroVideoCheck(pf, &m);
  m.face_ms = pf.timings.face_ms;
  m.stabilizer_ms = pf.timings.stabilizer_ms;
  m.warp_ms = pf.timings.mesh_ms + pf.timings.maps_ms + pf.timings.remap_ms;
  m.total_ms = pf.timings.total_ms;
  ZeroNonFinite(&m);
  return m;
}

}  // namespace steadiface_ros
