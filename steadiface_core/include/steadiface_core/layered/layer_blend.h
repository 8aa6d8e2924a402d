#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "steadiface_core/common/status.h"
#include "steadiface_core/common/tracking_lowpass.h"
#include "steadiface_core/layered/subject_region.h"

namespace steadiface {

/// Options of the per-frame mesh optimization that joins the two layers.
struct LayerBlendOptions {
  /// Width of the transition band where the mesh bends from the subject
  /// layer to the background layer, in jaw widths of the face (so it scales
  /// with the face's size in the output) [-].
  double band_width = 0.35;
  /// Fraction of the band that lies inside the region's outline, on the
  /// subject's periphery (hair, neck, shoulders), rather than on the
  /// background [0-1]. 1: the background is never bent.
  double band_inside = 1.0;
  /// The band's outer edge moves this many mesh-cell diagonals further
  /// inside the outline. Pixels are interpolated from their cell's four
  /// vertices, so a cell that reaches past the outline bends the background
  /// beside the subject unless all its vertices follow the background
  /// layer; 1 (with band_inside 1) keeps every pixel outside the outline on
  /// the background layer [cells].
  double outline_margin_cells = 1.0;
  /// The face's own cell follows the subject layer: vertices within this
  /// many cells (per axis) of the face's landmark centre, the point E_f puts
  /// at H, are pulled to the subject layer as firmly as held vertices, and
  /// the pull fades out over one more cell (continuous as the face moves
  /// across cells). Without it a face that is small for the mesh has no
  /// exact core, and its centre is interpolated partly from band vertices
  /// (vlog: 60 % of the layer offset reached the face). The cap below is then
  /// measured against the room left between this core and the band's outer
  /// edge, when that is less than band_width. 0 = off [cells].
  double face_core_cells = 1.0;
  /// Cap on the layer offset the band absorbs, measured at the head centre,
  /// as a fraction of the band's width [-]: the band's local stretch stays
  /// below about 1.5x this (the smoothstep's steepest slope). Beyond it one
  /// layer gives way (yield_to_subject). 0 = no cap.
  double max_offset = 0.35;
  /// The layer offset's slow part shifts the whole frame instead of bending
  /// the band, so the band absorbs only the offset's fast part (slow drift
  /// is intentional framing, such as a pan the face turns with, not shake).
  /// "Slow": a critically damped type-2 tracking loop at this natural
  /// frequency (ramps pass without lag) followed by a first-order low-pass
  /// at 5x it (the loop alone passes about 2 f / f_motion of faster
  /// motion). It moves the background with the face, so it is off by
  /// default: the head target keeps the offset within the band's reach
  /// (StabilizerOptions::subject_reach) instead. 0 = off (the band absorbs
  /// the whole offset) [Hz].
  double offset_lowpass_hz = 0.0;
  /// Data-term weight of the band's vertices (those in the core and beyond
  /// the band are held at their layer) [-].
  double band_data_weight = 0.02;
  /// Shape-preserving (similarity) term weight per triangle, Liu et al.
  /// 2009 [-].
  double shape_weight = 1.0;
  /// Temporal smoothness of the vertex offsets between frames [-].
  double temporal_weight = 0.05;
  /// Least singular-value ratio a cell of the joined mesh may have, or the
  /// background layer's own ratio for that cell if lower (the blend must
  /// not squeeze a cell below this). Where the cap is not enough (a layer
  /// offset that turns or shears across the band, as under violent shake),
  /// the offset is scaled towards the layer that does not give way
  /// (yield_to_subject) by bisection, as for protrusion [0-1). 0 = off.
  double min_cell_ratio = 0.5;
  /// Which layer gives way where the layers cannot be joined (the cap, the
  /// no-undefined-pixels pull and the no-squeezed-cell pull). true (the
  /// face first, as the global mode): the whole frame follows the subject
  /// layer in part, so the core always shows the subject layer's pose and
  /// the background steadies less; at full yield the mesh is the subject
  /// layer's, one global warp with the global mode's pose. false (the
  /// default: the background is never moved by the face): the subject
  /// follows the background layer in part (the head steadies less).
  bool yield_to_subject = false;
};

Status ValidateLayerBlendOptions(const LayerBlendOptions& options);

/// What the blend did this frame.
struct LayerBlendReport {
  bool layered = false;  ///< a region with blend > 0 was applied
  double blend = 0.0;    ///< the region's g
  /// Band width this frame, and its outer edge's distance outside the
  /// region's outline (the inner edge is band_px inside that) [output px].
  double band_px = 0.0, band_outer_px = 0.0;
  /// The band's width as the cap sees it: band_px, or less when the face's
  /// core (face_core_cells) lies closer than that to the band's outer edge
  /// [output px].
  double room_px = 0.0;
  /// The largest offset at the head centre the band absorbs before the cap
  /// (max_offset x room_px) [output px]; 0 when not layered.
  double reach_px = 0.0;
  /// The fast part of the layer offset at the head centre, before / after
  /// the cap [output px], and what shifts the whole frame: the slow part
  /// and, yielding to the subject, what the cap leaves over [output px].
  double offset_px = 0.0, capped_offset_px = 0.0, shift_px = 0.0;
  /// Fraction of the departure from the base (LayerBlend) kept after the
  /// protrusion pull [0-1] (1 = none).
  double protrusion_keep = 1.0;
  /// Fraction of the departure kept after the distortion pull
  /// (min_cell_ratio), of what the protrusion pull kept [0-1] (1 = none).
  double distortion_keep = 1.0;
  /// Worst (smallest) and 1st-percentile singular-value ratio of the cells'
  /// local maps, and cells whose orientation flipped (fold-over).
  double min_cell_ratio = 1.0, p01_cell_ratio = 1.0;
  int folded_cells = 0;
  /// The same ratio relative to the background layer's own map (the
  /// distortion the blend adds) [-].
  double min_added_ratio = 1.0;
  /// RMS change of the band vertices' offsets since the last frame [input px].
  double band_vertex_step_px = 0.0;
  double solve_ms = 0.0;
};

/// Joins two per-vertex source meshes (the subject layer's and the
/// background layer's, same grid of output vertices) into one:
///
///   min_d  w_b sum_k |d_k - T_k|^2                     (data, both layers)
///        + w_s sum_tri |S_tri(d)|^2                    (shape, Liu 2009)
///        + w_t sum_k |(d_k - T_k) - (d_k - T_k)^prev|^2 (temporal)
///   T_k = g S + a_k (D_k - S)
///   subject to d_k = T_k in the core and beyond the band
///
/// where d_k = source_k - background_k is the final mesh's offset from the
/// background layer, D_k = subject_k - background_k the layer offset, S the
/// slow part of the offset at the head centre (offset_lowpass_hz; it shifts
/// the whole frame), g the region's blend, a_k
/// the region's blend at vertex k (g in the core, falling to 0 over the band
/// by a smoothstep of the vertex's distance to the region's outline,
/// SubjectRegion::GridDistances) and w_b the band's data weight. The core
/// follows the subject layer and the rest of the frame the background layer
/// exactly; only the band's vertices are unknowns. Two things make the data
/// weight firm (as firm as a held vertex) where it must be: the band's edges,
/// so that a vertex crossing an edge as the face moves (held on one side,
/// free on the other) does not jump; and the face's core, the vertices
/// within face_core_cells of the landmark centre (the point E_f puts at H),
/// whose target is g D_k whatever the band's profile there, so that a face
/// that is small for the mesh still moves with its layer. Both fade
/// continuously. The cap below is measured against the room between the
/// face's core and the band's outer edge when that is narrower than the
/// band (LayerBlendReport::room_px, reach_px). S_tri is the similarity residual of
/// Liu et al.: each triangle's third vertex expressed in the frame of the
/// other two must keep the relative coordinates it has on the output grid,
/// so d may translate, rotate and scale locally but not shear. Four
/// triangles per cell. Linear least squares over the band's vertices
/// (Eigen SimplicialLDLT per frame; the held vertices enter the right-hand
/// side).
///
/// The cap: where |g (D_c - S)| at the head centre exceeds max_offset times
/// the band's width (or its room beside the face's core, if less), the band
/// absorbs only the cap's share of it; yielding to the
/// subject (yield_to_subject) the rest, g (1 - cap) (D_c - S), joins the whole
/// frame's shift, so the core still follows the subject layer; otherwise
/// the core follows the background layer in part.
///
/// Then no undefined pixels: every final vertex must land inside the input
/// frame (the cells are bilinear, so the whole cell then does); otherwise d
/// is scaled towards the base by bisection, d_k = base_k + s (d_k - base_k):
/// base_k = g D_k yielding to the subject (the layers mixed g of the way:
/// both are protrusion-free, so is each mix), else 0 (the background
/// layer). Then no squeezed cell: every cell's singular-value ratio must be
/// at least min_cell_ratio (or the base's own, if lower); otherwise d is
/// scaled further towards the base by bisection (a smaller scale keeps the
/// vertices inside: each vertex's excess is convex in the scale).
class LayerBlend {
 public:
  /// `u`, `v`: output pixel positions of the vertex columns and rows.
  LayerBlend(const std::vector<double>& u, const std::vector<double>& v,
             const LayerBlendOptions& options);

  /// Writes the joined mesh into `*source` (same layout as the inputs);
  /// `dt` is the time since the last frame [s] (<= 0 on the first);
  /// `input_width/height` bound the sources.
  void Blend(const std::vector<Eigen::Vector2f>& subject,
             const std::vector<Eigen::Vector2f>& background,
             const SubjectRegion& region, double dt, int input_width,
             int input_height, std::vector<Eigen::Vector2f>* source,
             LayerBlendReport* report);

  /// Blend weight a_k of each vertex of the last Blend [0-1].
  const std::vector<double>& vertex_blend() const { return alpha_; }
  /// Singular-value ratio of each cell of the last joined mesh [0-1].
  const std::vector<double>& cell_ratios() const { return ratios_scratch_; }
  void Reset() {
    has_previous_ = false;
    offset_lowpass_.Reset();
  }

 private:
  // Output px per input px, from the background mesh's middle row.
  double InputPerOutput(const std::vector<Eigen::Vector2f>& background) const;
  // Each vertex's blend weight a_k into alpha_, whether it is a band vertex
  // (an unknown), how firmly it keeps its target (firm_), and the band's
  // width, outer edge, room beside the face's core and reach into *r.
  void BandWeights(const SubjectRegion& region, std::vector<bool>* free_vertex,
                   LayerBlendReport* r);
  // Each vertex's pull towards the subject layer around the face's
  // landmark centre (face_core_cells) into core_ [0-1].
  void FaceCoreWeights(const SubjectRegion& region);
  // The layer offset subject - background at output point h (bilinear).
  Eigen::Vector2d OffsetAt(const std::vector<Eigen::Vector2f>& subject,
                           const std::vector<Eigen::Vector2f>& background,
                           const Eigen::Vector2d& h) const;
  // The offset at the head centre split into the whole frame's shift (its
  // slow part, and what the cap leaves when yielding to the subject) and
  // the fast part the band absorbs; returns the cap's scale [0-1].
  double SplitHeadOffset(const std::vector<Eigen::Vector2f>& subject,
                         const std::vector<Eigen::Vector2f>& background,
                         const SubjectRegion& region, double dt, double in_per_out,
                         Eigen::Vector2d* shift, Eigen::Vector2d* fast, LayerBlendReport* r);
  // The least-squares solve over the band's vertices; the rest keep their
  // targets.
  Eigen::VectorXd SolveBand(const Eigen::VectorXd& target, const std::vector<bool>& free_vertex);
  // The no-undefined-pixels pull: scales *departure by the largest factor
  // that keeps every vertex in the frame (or no farther out than the
  // base's); returns it.
  double PullInsideFrame(const std::vector<Eigen::Vector2d>& base_mesh,
                         const std::vector<double>& base_excess, double w1, double h1,
                         Eigen::VectorXd* departure) const;
  // The no-squeezed-cell pull: the largest scale of `departure` that keeps
  // every cell's ratio at min_cell_ratio (or the base's own, if lower).
  double PullUnsqueezed(const std::vector<Eigen::Vector2d>& base_mesh,
                        const Eigen::VectorXd& departure) const;
  // The final mesh from the offsets d (clamped to the frame), the band's
  // flicker into *r, and d kept for the next frame.
  void WriteMesh(const std::vector<Eigen::Vector2f>& background, const SubjectRegion& region,
                 const Eigen::VectorXd& d, const std::vector<double>& base_excess, double w1,
                 double h1, std::vector<Eigen::Vector2f>* source, LayerBlendReport* r);
  // Cell ratios of `source` into ratios_scratch_; folds, worst and 1st
  // percentile into *r.
  void MeasureCells(const std::vector<Eigen::Vector2f>& source,
                    LayerBlendReport* r);

  int cols_ = 0, rows_ = 0;
  std::vector<double> u_, v_;
  double cell_diagonal_ = 0.0;  // the largest cell's diagonal [output px]
  LayerBlendOptions options_;
  Eigen::SparseMatrix<double> shape_;   // w_s S^T S
  Eigen::SparseMatrix<double> system_;  // the band's unknowns only
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver_;
  std::vector<int> free_;  // unknown index of each coordinate, -1 = held
  std::vector<Eigen::Triplet<double>> triplets_;
  bool has_previous_ = false;
  Eigen::VectorXd d_previous_, e_previous_;
  // The offset's slow part at the head centre (offset_lowpass_hz > 0).
  TrackingLowpass offset_lowpass_;
  Eigen::Vector2d smooth_ = Eigen::Vector2d::Zero();
  std::vector<double> alpha_;
  std::vector<double> distance_;  // SubjectRegion::GridDistances per vertex
  std::vector<double> core_;      // FaceCoreWeights
  // How firmly each vertex keeps its target (the face's core, the band's
  // edges) [0-1].
  std::vector<double> firm_;
  std::vector<double> ratios_scratch_;
};

/// Singular-value ratios of a mesh's cells: for each cell, the ratio of the
/// smaller to the larger singular value of its local linear map (output ->
/// source), and whether any corner triangle flipped orientation. With
/// `reference`, the ratio of the map relative to the reference's (the
/// distortion one mesh adds to the other). Returns the ratios in `*ratio`
/// (one per cell) and the number of flipped cells.
int CellRatios(int cols, int rows, const std::vector<double>& u,
               const std::vector<double>& v,
               const std::vector<Eigen::Vector2f>& source,
               const std::vector<Eigen::Vector2f>* reference,
               std::vector<double>* ratio);

}  // namespace steadiface
