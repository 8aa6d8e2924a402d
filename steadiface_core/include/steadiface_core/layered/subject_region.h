#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/face/face_observation.h"
#include "steadiface_core/gyro/row_rotations.h"
#include "steadiface_core/camera/output_geometry.h"

namespace steadiface {

/// Shape and dynamics of the subject region of the layered warp:
/// the part of the output that follows the face-following (subject) layer.
/// Lengths are relative to the face as the 68 landmarks see it: the jaw
/// width (landmarks 0-16) and the brow-to-chin height.
struct SubjectRegionOptions {
  /// Head ellipse half-width over the jaw width (ears and hair) [-].
  double head_width_scale = 0.7;
  /// Hair above the brows, as a fraction of the brow-to-chin height [-].
  double head_top_scale = 0.7;
  /// Include neck and shoulders below the chin (they move with the head).
  bool torso = true;
  /// Shoulder half-width over the jaw width [-].
  double shoulder_width_scale = 1.5;
  /// Neck half-width over the jaw width [-].
  double neck_width_scale = 0.35;
  /// Time constant of the region's shape smoothing (its size and the chin's
  /// place on it; the position is each frame's, so a moving subject does not
  /// lag into the band) [s].
  double smoothing_s = 0.15;
  /// The blend weight moves by at most dt / ramp_s per frame: the warp
  /// returns to one global warp (or leaves it) over at least this time [s].
  double ramp_s = 0.5;
};

Status ValidateSubjectRegionOptions(const SubjectRegionOptions& options);

/// The subject region of one frame, in output pixels: a head ellipse, a neck
/// box and a shoulder ellipse reaching below the frame, and the blend weight
/// g in [0, 1] that scales the whole region (0 = one global warp).
struct SubjectRegion {
  bool valid = false;
  Eigen::Vector2d head_centre = Eigen::Vector2d::Zero();
  /// The landmark centre (what E_f puts at H) [px]: the middle of the face,
  /// below the head ellipse's centre. NaN when not measured (a region built
  /// by hand): the layer blend then holds no face core.
  Eigen::Vector2d face_centre = Eigen::Vector2d::Constant(NAN);
  Eigen::Vector2d head_axes = Eigen::Vector2d::Zero();  ///< half-axes [px]
  Eigen::Vector2d chin = Eigen::Vector2d::Zero();
  double jaw_width = 0.0;    ///< [px]
  double face_height = 0.0;  ///< brow to chin [px]
  bool torso = true;
  double neck_half_width = 0.0;
  Eigen::Vector2d shoulder_centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d shoulder_axes = Eigen::Vector2d::Zero();
  double blend = 0.0;       ///< g [0-1]
  double blend_step = 0.0;  ///< |g - g_previous| this frame (0 on the first)

  /// Approximate signed distance to the region's outline [px]: negative
  /// inside, positive outside (exact for circles; for ellipses scaled by the
  /// smaller half-axis, which keeps the band no narrower than asked).
  double SignedDistance(const Eigen::Vector2d& p) const;

  /// The signed distance to the outline at every vertex of a grid (vertex
  /// columns at u, rows at v, as a mesh's) into `*sd` [px]. Unlike
  /// SignedDistance it is right inside where the shapes overlap (under the
  /// chin the nearer of the two outlines lies inside the other shape, and
  /// SignedDistance underestimates the depth by up to the neck's width):
  /// inside, the region is rasterized at a quarter of the grid's cell and
  /// distance-transformed, less half the raster's diagonal and never
  /// shallower than SignedDistance; outside it is SignedDistance. Inside, it
  /// is within the raster's resolution of the true depth and at most about
  /// 1 px deeper (the rasterized outline covers the pixels it touches). An
  /// outline more than one cell beyond the grid (shoulders below the frame)
  /// is not seen: the depth there is to the outline within the grid.
  void GridDistances(const std::vector<double>& u, const std::vector<double>& v,
                     std::vector<double>* sd) const;
};

/// Builds the subject region from this frame's landmarks, mapped into the
/// output through the subject layer's pose, smooths it over time and ramps
/// its blend weight (towards 1 with a usable face, 0 without). While the face
/// is missing the last region is kept and the blend ramps to 0. Causal; one per
/// stream.
class SubjectRegionTracker {
 public:
  explicit SubjectRegionTracker(const SubjectRegionOptions& options)
      : options_(options) {}

  /// `face` may be null or invalid. `blend_target` in [0, 1]: 1 while the
  /// stabilizer uses a face, 0 without (w_f's presence target; the ramp
  /// makes it continuous, and the subject layer's pose already carries w_f's
  /// other factors); `dt` the time since the last frame
  /// [s] (<= 0 on the first frame: the blend starts at its target).
  const SubjectRegion& Update(const CameraModel& model,
                              const OutputGeometry& output,
                              const Eigen::Quaterniond& R_v,
                              const Eigen::Vector2d& t,
                              const RowRotations& rows,
                              const FaceObservation* face, double blend_target,
                              double dt);
  const SubjectRegion& region() const { return region_; }
  void Reset() { region_ = SubjectRegion(); }

 private:
  // This frame's region from the landmarks, unsmoothed (invalid without a
  // usable face).
  SubjectRegion Measure(const CameraModel& model, const OutputGeometry& output,
                        const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                        const RowRotations& rows, const FaceObservation* face) const;
  const SubjectRegionOptions options_;
  SubjectRegion region_;
};

}  // namespace steadiface
