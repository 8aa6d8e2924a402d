#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/gyro/row_rotations.h"
#include "steadiface_core/layered/layer_blend.h"
#include "steadiface_core/layered/subject_region.h"
#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/warp/protrusion.h"

namespace steadiface {

/// How the output is composed from the virtual cameras.
enum class WarpMode {
  /// One virtual camera for the whole frame (the paper's): the subject
  /// layer's pose.
  kGlobal,
  /// Two layers (issue 15): inside the subject region the mesh follows the
  /// face-following (subject) layer, outside it the background layer (the
  /// gyro-only pose), joined across a band by a per-frame mesh
  /// optimization (LayerBlend).
  kLayered,
  /// Two layers composited (Compositor): the subject, cut out by a matte,
  /// warped by the face-following layer's pose, over the background layer
  /// (the gyro-only pose); what the subject uncovers comes from a plate of
  /// the scene built from recent frames.
  kComposite,
};

/// Parses "global" / "layered" / "composite".
Status ParseWarpMode(const std::string& name, WarpMode* mode);
const char* WarpModeName(WarpMode mode);

/// Options of the layered warp.
struct LayeredWarpOptions {
  /// The subject region and its blend weight.
  SubjectRegionOptions region;
  /// The mesh optimization across the band.
  LayerBlendOptions blend;
  /// Mesh cells across / down in layered mode (denser than the global
  /// mesh, so the band spans several cells) [count].
  int mesh_cols = 32;
  int mesh_rows = 18;
};

/// Options of the mesh warp (image composition).
struct WarpOptions {
  /// Global (one virtual camera) or layered (subject + background).
  WarpMode mode = WarpMode::kGlobal;
  /// Used in layered mode; its subject region also in composite mode.
  LayeredWarpOptions layered;
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
  /// Render by sampling the mesh directly (SampleMesh: source coordinates
  /// stepped per mesh cell in fixed point, bilinear in SIMD registers, no
  /// dense maps); the output is bit-for-bit cv::remap's with the
  /// fixed-point maps. Otherwise dense maps are built and cv::remap runs.
  bool direct_sampling = true;
  /// Dense maps (direct_sampling off): OpenCV's fixed-point maps (CV_16SC2
  /// + CV_16UC1, 1/32 px; faster remap), otherwise CV_32FC1 x 2.
  bool fixed_point_maps = true;
  /// Worker threads for map building and remap; 0 keeps OpenCV's default.
  /// Note: cv::setNumThreads is process-wide.
  int num_threads = 0;
  /// Boundary samples per output edge for the protrusion check [count].
  int protrusion_samples_per_edge = 16;
};

Status ValidateWarpOptions(const WarpOptions& options);

/// True when `mode` and `layered` equal those of `options` (field by field).
bool SameLayering(WarpMode mode, const LayeredWarpOptions& layered, const WarpOptions& options);

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
  /// Dense maps (0 with direct sampling).
  double maps_ms = 0.0;
  /// cv::remap, or the direct sampling.
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
  /// Layered mode: the subject layer's mesh (R_v, t), the background
  /// layer's (R_b, t_b) and their join across the region's band
  /// (LayerBlend); `dt` is the time since the last frame [s]. With no
  /// region (or blend 0) the mesh is the background layer's. Needs mode ==
  /// kLayered.
  Status ComputeLayeredMesh(const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                            const Eigen::Quaterniond& R_b, const Eigen::Vector2d& t_b,
                            const RowRotations& rows, const SubjectRegion& region,
                            double dt);
  /// The dynamic crop: output pixels tile (1 - 2 r) of the frame from the
  /// next mesh on (OutputGeometry::WithCropRatio); the output size stays.
  void SetCropRatio(double r);
  /// Forgets the layered mesh's temporal state (time jumped).
  void Reset() {
    if (blend_ != nullptr) blend_->Reset();
  }
  /// Dense maps from the last mesh.
  void BuildMaps();
  /// Remaps `input` (8-bit, 1-4 channels, the camera model's size) into
  /// `output` with the last maps.
  Status Remap(const cv::Mat& input, cv::Mat* output);
  /// Renders `input` through the last mesh: SampleMesh with
  /// direct_sampling, else BuildMaps and Remap.
  Status Render(const cv::Mat& input, cv::Mat* output);
  /// ComputeMesh and Render.
  Status Warp(const cv::Mat& input, const Eigen::Quaterniond& R_v,
              const Eigen::Vector2d& t, const RowRotations& rows,
              cv::Mat* output);

  const WarpMesh& mesh() const { return mesh_; }
  /// Layered mode: the two layers' meshes of the last ComputeLayeredMesh,
  /// the blend's report and per-vertex blend weights.
  const std::vector<Eigen::Vector2f>& subject_mesh() const { return subject_source_; }
  const std::vector<Eigen::Vector2f>& background_mesh() const { return background_source_; }
  const LayerBlendReport& blend_report() const { return blend_report_; }
  const LayerBlend* layer_blend() const { return blend_.get(); }
  const WarpTimings& timings() const { return timings_; }
  const OutputGeometry& output_geometry() const { return output_; }
  const ProtrusionGeometry& protrusion() const { return protrusion_; }
  const CameraModel& camera_model() const { return model_; }
  /// Float maps of the last mesh (builds the dense maps; converted when
  /// fixed-point maps are used); for tests and tools.
  void FloatMaps(cv::Mat* map_x, cv::Mat* map_y);

 private:
  Warper(const CameraModel& model, const WarpOptions& options,
         const OutputGeometry& output);

  const CameraModel model_;
  const WarpOptions options_;
  // The crop in effect (SetCropRatio) and its protrusion boundary.
  OutputGeometry output_;
  ProtrusionGeometry protrusion_;
  // Fills `source`/`source_row` with one pose's mesh.
  Status MeshForPose(const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                     const RowRotations& rows, std::vector<Eigen::Vector2f>* source,
                     std::vector<float>* source_row) const;

  WarpMesh mesh_;
  std::vector<Eigen::Vector2f> subject_source_, background_source_;
  std::vector<float> row_scratch_;
  std::unique_ptr<LayerBlend> blend_;  // layered mode
  LayerBlendReport blend_report_;
  cv::Mat map1_, map2_;  // fixed point: CV_16SC2 + CV_16UC1; float: 2x 32FC1
  WarpTimings timings_;
};

}  // namespace steadiface
