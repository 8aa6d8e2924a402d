#pragma once

#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface/FaceLandmarks.h"
#include "steadiface/StabilizerState.h"
#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/face/face_types.h"
#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/pipeline/pipeline.h"

namespace steadiface_ros {

/// sensor_msgs/CameraInfo -> core intrinsics of the image as it arrives,
/// i.e. after the message's binning and region of interest are applied (as
/// image_geometry does). Rejects an uncalibrated info (K all zero), unknown
/// distortion models and inconsistent sizes with a message naming the field.
steadiface::Status ToCameraIntrinsics(const sensor_msgs::CameraInfo& info,
                                      steadiface::CameraIntrinsics* out);

/// sensor_msgs/Imu -> one gyro sample (stamp and angular_velocity). Values
/// are copied unchecked: the orientation timeline validates and counts them.
steadiface::GyroSample ToGyroSample(const sensor_msgs::Imu& imu);
/// sensor_msgs/Imu -> one accelerometer reading (stamp, linear_acceleration).
/// False when the message has none: linear_acceleration_covariance[0] == -1
/// (the message's convention for "not provided"), or all three zero.
bool ToAccelSample(const sensor_msgs::Imu& imu, steadiface::AccelSample* out);

/// Quaternion conversions. ToEigen normalizes; a zero or non-finite message
/// quaternion yields false.
bool ToEigen(const geometry_msgs::Quaternion& msg, Eigen::Quaterniond* q);
geometry_msgs::Quaternion ToMsg(const Eigen::Quaterniond& q);

/// A rotation-only transform.
geometry_msgs::Transform ToTransformMsg(const Eigen::Quaterniond& q);

/// Validates an image message before touching its memory (encoding, size,
/// step, data length) and wraps or converts it to an 8-bit cv::Mat: mono8
/// stays 1 channel, bgr8 stays 3, bgra8 4; rgb8/rgba8 become bgr8;
/// yuv422 (UYVY) and yuyv / yuv422_yuy2 (YUYV) become bgr8; bayer_*8/16 are
/// demosaiced to bgr8; 16-bit images (mono16, bgr16, ...) are scaled from
/// their full range to 8 bits. Float and signed images (depth maps) are
/// refused with a message naming the encoding. `*image` may share the
/// message's memory: keep the message alive while using it.
steadiface::Status ToCvImage(const sensor_msgs::Image& msg, cv::Mat* image);

/// cv::Mat -> sensor_msgs/Image with `header` and `encoding` (the caller
/// names the encoding of the Mat's pixel type), rows copied tightly (step =
/// width * pixel size): what cv_bridge::CvImage::toImageMsg gives, without
/// linking cv_bridge, whose OpenCV imgcodecs brings ~110 libraries.
sensor_msgs::ImagePtr ToImageMsg(const std_msgs::Header& header, const std::string& encoding,
                                 const cv::Mat& image);

/// sensor_msgs/CompressedImage (jpeg or png, as compressed_image_transport
/// publishes it on <image>/compressed) -> a decoded image message with the
/// same header: mono8/bgr8/bgra8, or mono16/bgr16 for a 16-bit png. A
/// compressedDepth payload, an unknown format or undecodable data is an
/// error naming it.
steadiface::Status FromCompressedImage(const sensor_msgs::CompressedImage& msg,
                                       sensor_msgs::ImagePtr* out);

/// Output camera_info for the stabilized image: the virtual intrinsics,
/// no distortion, identity R, P = [K | 0].
sensor_msgs::CameraInfo ToCameraInfo(const steadiface::CameraIntrinsics& k,
                                     const std_msgs::Header& header);

steadiface::FaceLandmarks ToMsg(const steadiface::FaceInfo& face,
                                const std_msgs::Header& header);
/// ~landmarks_in -> 68 pixel points (empty when !valid) and confidence.
steadiface::Status FromMsg(const steadiface::FaceLandmarks& msg,
                           std::vector<Eigen::Vector2d>* points,
                           double* confidence);

steadiface::StabilizerState ToMsg(const steadiface::PipelineFrame& frame,
                                  const std_msgs::Header& header,
                                  bool gyro_extrapolated);

}  // namespace steadiface_ros
