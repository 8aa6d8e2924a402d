#pragma once

#include <string>

#include <sensor_msgs/CameraInfo.h>

#include "steadiface_bag/bag_writer.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace steadiface_bag {

/// What the report needs to know of the run besides the sink's records.
struct ReportInputs {
  std::string in;     ///< input bag path
  std::string truth;  ///< simulator ground truth CSV ("" = none)
  std::string
      plot_dir;  ///< trajectories for scripts/plot_report.py ("" = none)
  std::string plot_name = "bag";
  bool gyro_only = false;
  double elapsed_s = 0.0;  ///< wall time of the run
  double crop_ratio = 0.0;
  /// f_v / f_r (camera/virtual_focal_scale): with the output intrinsics it
  /// gives the output px per unit of principal offset.
  double virtual_focal_scale = 1.0;
  bool have_input_info = false;
  sensor_msgs::CameraInfo input_info;
};

/// The report JSON: counters, timings, jitter that needs no ground truth
/// and, with `truth`, the scorecard's ground-truth jitter (the true head
/// centre and a far-background direction mapped through each frame's warp).
/// Also writes the plot trajectories when `plot_dir` is set.
std::string MakeReport(const ReportInputs& r, const BagSink& sink,
                       const steadiface_ros::WrapperStatus& ws);

/// The per-frame pose CSV of --trajectory (full precision).
void WriteTrajectory(const std::string& path, const BagSink& sink);

}  // namespace steadiface_bag
