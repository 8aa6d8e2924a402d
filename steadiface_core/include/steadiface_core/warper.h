#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera_model.h"
#include "steadiface_core/output_geometry.h"
#include "steadiface_core/protrusion.h"
#include "steadiface_core/row_rotations.h"
#include "steadiface_core/status.h"

namespace steadiface {

/// Options of the mesh warp (image composition).
struct WarpOptions {
  /// Output crop and size.
  OutputOptions output;
  /// Mesh cells across the output width [count].
  int mesh_cols = 16;
  /// Mesh cells down the output height [count]; each cell row spans about
  /// 1/mesh_rows of the frame, i.e. one rolling-shutter band.
  int mesh_rows = 12;
  /// With lens distortion, mesh cells are refined to at most this size so
  /// the bilinear map follows the lens [px]. Ignored without distortion.
  int distortion_cell_px = 16;
  /// Rolling-shutter fixed-point iterations per vertex (see
  /// VirtualToRealPixelRS) [count].
  int fixed_point_iterations = 5;
  /// Use OpenCV's fixed-point maps (CV_16SC2 + CV_16UC1, 1/32 px); faster
  /// remap. Otherwise CV_32FC1 x 2.
  bool fixed_point_maps = true;
  /// Worker threads for map building and remap; 0 keeps OpenCV's default.
  /// Note: cv::setNumThreads is process-wide.
  int num_threads = 0;
  /// Boundary samples per output edge for the protrusion check [count].
  int protrusion_samples_per_edge = 16;
};

Status ValidateWarpOptions(const WarpOptions& options);

/// The warp mesh: for a grid of output vertices, the raw input pixel each one
/// samples.
struct WarpMesh {
  int cols = 0;  ///< vertices across = cells + 1
  int rows = 0;  ///< vertices down = cells + 1
  /// Output pixel coordinates of vertex columns / rows.
  std::vector<double> u, v;
  /// Source (raw input) pixel of vertex (i, j) at [j * cols + i].
  std::vector<Eigen::Vector2f> source;
  /// Input row each vertex landed on (rolling-shutter fixed point).
  std::vector<float> source_row;
};

/// Per-stage timings of the last Warp() [ms].
struct WarpTimings {
  double mesh_ms = 0.0;
  double maps_ms = 0.0;
  double remap_ms = 0.0;
};

/// Rolling-shutter-aware mesh warp (paper §2-3, image composition): each
/// output vertex is mapped back through Π^-1 with the real rotation of the
/// input row it lands on, lens distortion is folded into the same map, the
/// mesh is interpolated bilinearly to dense maps, and cv::remap (bilinear,
/// black constant border) produces the cropped, scaled output. Buffers are
/// reused between frames. Not thread-safe; one instance per stream.
class Warper {
 public:
  static Status Create(const CameraModel& model, const WarpOptions& options,
                       std::unique_ptr<Warper>* out);

  /// Maps the mesh for pose (R_v, t) and the frame's row rotations. Refuses
  /// non-finite poses and poses that put part of the output behind the
  /// camera.
  Status ComputeMesh(const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                     const RowRotations& rows);
  /// Dense maps from the last mesh.
  void BuildMaps();
  /// Remaps `input` (8-bit, 1-4 channels, the camera model's size) into
  /// `output` with the last maps.
  Status Remap(const cv::Mat& input, cv::Mat* output);
  /// All three.
  Status Warp(const cv::Mat& input, const Eigen::Quaterniond& R_v,
              const Eigen::Vector2d& t, const RowRotations& rows,
              cv::Mat* output);

  const WarpMesh& mesh() const { return mesh_; }
  const WarpTimings& timings() const { return timings_; }
  const OutputGeometry& output_geometry() const { return output_; }
  const ProtrusionGeometry& protrusion() const { return protrusion_; }
  const CameraModel& camera_model() const { return model_; }
  /// Float maps of the last BuildMaps (built on demand when fixed-point maps
  /// are used); for tests and tools.
  void FloatMaps(cv::Mat* map_x, cv::Mat* map_y) const;

 private:
  Warper(const CameraModel& model, const WarpOptions& options,
         const OutputGeometry& output);

  const CameraModel model_;
  const WarpOptions options_;
  const OutputGeometry output_;
  const ProtrusionGeometry protrusion_;
  WarpMesh mesh_;
  cv::Mat map1_, map2_;  // fixed point: CV_16SC2 + CV_16UC1; float: 2x 32FC1
  WarpTimings timings_;
};

}  // namespace steadiface
