#pragma once

#include <string>
#include <vector>

#include "steadiface_bag/bag_reader.h"

namespace steadiface_bag {

/// What steadiface_bag runs (its command line).
struct BagRunOptions {
  std::string in;  ///< the input bag
  /// Outputs, each empty for none: the stabilized bag, the side-by-side
  /// video, the report JSON, the per-frame pose CSV.
  std::string out, video, report, trajectory;
  /// The simulator's ground truth (empty: <in>.truth.csv when it exists).
  std::string truth;
  /// Trajectories for scripts/plot_report.py (empty: none), and their name.
  std::string plot_dir, plot_name = "bag";
  /// Parameter files over config/default.yaml, later ones winning.
  std::vector<std::string> params;
  BagTopics topics;
  /// The output bag's chunk compression: none, lz4 or bz2.
  std::string compress = "none";
  bool debug_overlay = false;        ///< the video shows the debug overlay
  bool debug_images_in_bag = false;  ///< the debug images also go into `out`
  bool gyro_only = false;            ///< no face: w_f = 0
  bool quiet = false;                ///< no progress or summary
  bool no_pipeline = false;          ///< render each frame before the next
  bool rosbag_reader = false;        ///< read through rosbag::View
  bool verify_checksums = false;     ///< check LZ4 chunks in the indexed reader
  double start_stamp = 0.0;          ///< images stamped before this are skipped [s]
  /// A file of image stamps [s], one per line: only those are processed.
  std::string only_stamps;
};

/// Processes a bag offline through the same StabilizerWrapper as the
/// nodelet (no ROS master), as fast as the machine allows. Three stages on
/// three threads: the reader decodes messages in bag order into a bounded
/// queue; this thread runs the wrapper exactly as the nodelet's callbacks
/// would (same order, same results); the writer drains a bounded queue of
/// bag writes. Bounded both ways, so memory stays at a few frames whatever
/// the bag size. Errors and progress go to stderr. Returns the process's
/// exit status: 0 frames came out, 1 a failure, 2 a bad option.
int RunBag(const BagRunOptions& options);

}  // namespace steadiface_bag
