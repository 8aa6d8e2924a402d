#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "steadiface/SteadifaceConfig.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/pipeline/frame_scheduler.h"
#include "steadiface_core/pipeline/pipeline.h"

namespace steadiface_ros {

/// Where parameters come from: the ROS parameter server (node, nodelet) or
/// a YAML file (the offline bag tool, no master). Keys are '/'-separated
/// paths, e.g. "weights/fit".
class ParamSource {
 public:
  virtual ~ParamSource() = default;
  virtual bool Get(const std::string& key, double* v) const = 0;
  virtual bool Get(const std::string& key, int* v) const = 0;
  virtual bool Get(const std::string& key, bool* v) const = 0;
  virtual bool Get(const std::string& key, std::string* v) const = 0;
  virtual bool Get(const std::string& key, std::vector<double>* v) const = 0;
};

/// ~private namespace of a node or nodelet.
std::unique_ptr<ParamSource> RosParams(const ros::NodeHandle& private_nh);
/// A YAML file (same keys as config/default.yaml). Later files override
/// earlier ones.
steadiface::Status YamlParams(const std::vector<std::string>& paths,
                              std::unique_ptr<ParamSource>* out);

/// ROS-layer options (the core's are in PipelineOptions).
struct WrapperOptions {
  /// Frame of the published stabilized image; empty = input frame + suffix.
  std::string camera_frame;
  /// Intrinsics for images that come without a camera_info message: a
  /// camera_calibration YAML or INI file, as file:///abs/path,
  /// package://pkg/path or a plain path. Empty = camera_info messages only.
  /// A camera_info message, when there is one, wins.
  std::string camera_info_url;
  /// How image_raw arrives: raw, or compressed (the image_transport plugin
  /// when installed, else image_raw/compressed and the built-in decoder).
  std::string image_transport = "raw";
  std::string stabilized_suffix = "_stabilized";
  std::string world_frame;
  bool publish_world_tf = true;
  /// Look up the IMU -> camera rotation in TF when the IMU frame differs.
  bool imu_extrinsics_from_tf = true;
  /// The stream's rules: the wait for gyro coverage, the late-frame
  /// policy, the frame queue, the IMU timeout and gap warning, the pipelined
  /// hold (keys max_gyro_wait, late_frame_policy, frame_queue_size,
  /// imu_timeout, imu_gap_warn, pipeline_hold). No IMU for imu_timeout also
  /// raises the ERROR diagnostic.
  steadiface::FrameSchedulerOptions scheduler;
  /// Expected rates for the FrequencyStatus diagnostics [Hz] (0 = any).
  double expected_image_rate = 0.0;
  double expected_imu_rate = 0.0;
  /// Publish frames unstabilized (centre crop) when no gyro is available.
  bool passthrough_without_imu = true;
  /// Two-stage pipeline: frame n is rendered on a worker thread while frame
  /// n+1 goes through face, check and stabilizer; frame n is published
  /// when frame n+1 is done (or after pipeline_hold, or at the end). Uses a
  /// second core; adds up to one frame of latency. The bag tool turns it on.
  /// (scheduler.pipeline_hold_s: the next frame is processed about a frame
  /// period plus the readout and the gyro's delay later: a shorter hold
  /// overlaps frames only when they queue up, i.e. the node falls behind.)
  bool pipelined = false;
};

/// One row of the parameter table (config/parameters.yaml, the one place
/// that states each key's type, range, choices and dynamic_reconfigure
/// name; scripts/dev/gen_parameters.py writes it into the build).
enum class ParameterType { kDouble, kInt, kBool, kString, kList };
struct ParameterSpec {
  const char* key;           ///< '/'-separated path in the private namespace
  ParameterType type;
  double min, max;           ///< numbers: the valid range (inclusive)
  const char* choices;       ///< strings: '|'-separated valid values ("" = any)
  const char* dynamic_name;  ///< its dynamic_reconfigure name ("" = none)
  bool read_by_node;         ///< false: only the launch files read it
};
/// Every key, in the table's order.
const std::vector<ParameterSpec>& ParameterTable();

/// Loads every option, validating each against the parameter table; errors
/// name the key and its valid range or choices.
steadiface::Status LoadOptions(const ParamSource& params,
                               steadiface::PipelineOptions* pipeline,
                               WrapperOptions* wrapper);

/// The offline tools' start: config/default.yaml of the installed package
/// (ros::package), then `overlays` in order (later ones win), through
/// LoadOptions.
steadiface::Status LoadPackageOptions(const std::vector<std::string>& overlays,
                                      steadiface::PipelineOptions* pipeline,
                                      WrapperOptions* wrapper);

/// dynamic_reconfigure <-> the options it changes at run time (the
/// stabilizer's weights and terms, the warp mode, the layered warp's band and
/// region). Both are generated from config/parameters.yaml (each run-time
/// key's field). ApplyConfig keeps each low threshold below its high one.
void ApplyConfig(const steadiface::SteadifaceConfig& config,
                 steadiface::PipelineOptions* pipeline);
steadiface::SteadifaceConfig ConfigFromOptions(const steadiface::PipelineOptions& pipeline);

}  // namespace steadiface_ros
