#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/sim/scene_renderer.h"

namespace steadiface {
namespace sim {

/// The shape given to a face photo so that it turns like a head: a depth per
/// texel behind the photo's plane.
struct HeadReliefOptions {
  /// Depth of the head's turning axis behind the face's plane: the skull's
  /// centre, about which a head yaws and nods [m].
  double pivot_depth_m = 0.09;
  /// The head's outline (the billboard's elliptical mask) reaches the pivot's
  /// depth at this fraction of the ellipse's radius; beyond it, the mask's
  /// feathered rim stays at that depth [-].
  double outline_radius = 0.85;
  /// The head's breadth where its sides reach the pivot's depth, in face
  /// widths [-]; 0: the billboard's outline (outline_radius of its width:
  /// 1.62 face widths for the default portrait, which includes hair and
  /// background around the face). A real head is about as broad as its
  /// face (a 15 cm face, a 15.5-16.5 cm head); a broad relief puts the
  /// face's sides, where its jaw landmarks sit, nearly in the plane of its
  /// front. Beyond that breadth the relief stays at the pivot's depth.
  double breadth_face_widths = 0.0;
  /// The nose: how far its tip stands in front of the face's plane [m], its
  /// width and length (Gaussian sigmas, as fractions of the face's width)
  /// and its centre below the landmarks' centre [face widths].
  double nose_height_m = 0.02;
  double nose_sigma_x = 0.09, nose_sigma_y = 0.18;
  double nose_below = 0.08;
  /// The face's own depths: at each of the photo's 68 landmarks the mean
  /// face's (sim/mean_face.h), scaled to the photo's jaw width, carried
  /// between them by Gaussians and fading into the ellipsoid beyond them
  /// (AddMeanFaceDepths). Replaces the Gaussian nose. Needs the photo's
  /// landmarks (SimulatorOptions::face_landmarks); `steadiface_evaluate
  /// --head-model mean-face` turns it on with a breadth of 1.1.
  bool mean_face = false;
  /// Those Gaussians' sigma [face widths between the jaw ends]: 0.12 made
  /// the interpolation overshoot between landmarks (creases).
  double mean_face_sigma = 0.06;
};

/// Reads a photo's 68 landmarks: one "x y" per line [photo px] (anything
/// after the 68th is ignored). False when the file has fewer.
bool ReadPhotoLandmarks(const std::string& path, std::vector<Eigen::Vector2d>* out);

/// Adds the mean face's (MeanFace68) depths at the photo's 68 landmarks
/// (`landmarks_uv`, texels; `metres_per_texel`) to an ellipsoid relief
/// `depth` (MakeHeadRelief without its nose): the landmarks get the mean
/// face's depths, with the eyes' mean on the photo's plane (so the turning
/// axis is the pivot's depth behind the eyes); Gaussian radial basis
/// functions (`sigma_face_widths`) interpolate the change between them and
/// let it fade beyond.
/// Fails (false, `depth` unchanged) without 68 finite landmarks or a jaw
/// wider than 1 texel.
bool AddMeanFaceDepths(const std::vector<Eigen::Vector2d>& landmarks_uv,
                       double metres_per_texel, double sigma_face_widths,
                       cv::Mat* depth);

/// The depth of a face billboard's texture (`texture_size` texels, the
/// billboard's `anchor_px` and `metres_per_px`, the landmarks' centre
/// `face_centre_uv` and the face's width `face_width_px` in texels): an
/// ellipsoid whose front is the photo's plane and whose outline curves back
/// to the pivot's depth (across, at options.breadth_face_widths when set),
/// plus a nose. CV_32F, metres along the billboard's
/// local z (away from the viewer; the nose is negative).
cv::Mat MakeHeadRelief(const cv::Size& texture_size,
                       const Eigen::Vector2d& face_centre_uv,
                       double face_width_px, const HeadReliefOptions& options);

/// The relief's depth at texel uv (bilinear; the border's beyond) [m].
double ReliefDepth(const cv::Mat& depth, const Eigen::Vector2d& uv);

/// Renders a billboard with a relief (b.depth_m) as RenderBoard renders a
/// flat one: into `layer` (BGRA, alpha 0 where it is not), with a rolling
/// shutter (each texel seen at its own row's time, the poses taken per band
/// of `band` rows), hidden surfaces removed (a depth buffer) and the faces
/// turned away from the camera culled. The texture is a grid of triangles
/// every `grid_texels`, each drawn with its texels interpolated bilinearly.
void RenderRelief(const CameraIntrinsics& k,
                  const std::function<double(double)>& row_time,
                  const std::function<Pose(double)>& camera_pose,
                  const Billboard& b, int band, cv::Mat* layer,
                  int grid_texels = 2);

/// Where a camera ray first meets a relief billboard: the texel uv, or false
/// when it misses the texture. `origin` and `ray` in the world, `P` the
/// billboard's pose.
bool IntersectRelief(const Billboard& b, const Pose& P,
                     const Eigen::Vector3d& origin, const Eigen::Vector3d& ray,
                     Eigen::Vector2d* uv);

}  // namespace sim
}  // namespace steadiface
