#include "steadiface_core/layered/layer_blend.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <Eigen/Dense>

#include "steadiface_core/common/stopwatch.h"

namespace steadiface {
namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Ratio of the smaller to the larger singular value of a 2x2 map.
double SingularRatio(const Eigen::Matrix2d& M) {
  const double f2 = M.squaredNorm();
  const double det = M.determinant();
  const double disc = std::sqrt(std::max(0.0, f2 * f2 - 4.0 * det * det));
  const double s1 = std::sqrt(std::max(0.0, 0.5 * (f2 + disc)));
  const double s2 = std::sqrt(std::max(0.0, 0.5 * (f2 - disc)));
  return s1 > 0 ? s2 / s1 : 0.0;
}

// The four corner triangles of cell (a, b, c, e) = (i,j), (i+1,j),
// (i+1,j+1), (i,j+1): vertex V1 and its two neighbours V2, V3 along the
// cell's edges, counter-clockwise in the output (x right, y down).
struct Triangle {
  int v1, v2, v3;
};

// The data weight of a firm vertex (the face's core, the band's edges) over
// the shape weight: a firm vertex lands within ~1 % of its target.
constexpr double kFirmWeight = 100.0;
// The band's firm edges: the fraction of the band, from each edge, over
// which the firmness fades out.
constexpr double kFirmEdge = 0.5;
// The face's core fades in over this many cell diagonals inside the band's
// outer edge.
constexpr double kCoreFade = 0.25;

double Excess(const Eigen::Vector2d& p, double w1, double h1) {
  return std::max({0.0, -p.x(), p.x() - w1, -p.y(), p.y() - h1});
}

}  // namespace

Status ValidateLayerBlendOptions(const LayerBlendOptions& o) {
  auto in = [](double v, double lo, double hi) {
    return std::isfinite(v) && v >= lo && v <= hi;
  };
  std::ostringstream err;
  if (!in(o.band_width, 0.02, 10.0)) {
    err << "warp.layered.band_width must be in [0.02, 10] jaw widths, got "
        << o.band_width;
  } else if (!in(o.band_inside, 0.0, 1.0)) {
    err << "warp.layered.band_inside must be in [0, 1], got " << o.band_inside;
  } else if (!in(o.max_offset, 0.0, 10.0)) {
    err << "warp.layered.max_offset must be in [0, 10] band widths (0 = no "
           "cap), got "
        << o.max_offset;
  } else if (!in(o.outline_margin_cells, 0.0, 4.0)) {
    err << "warp.layered.outline_margin must be in [0, 4] cells, got "
        << o.outline_margin_cells;
  } else if (!in(o.face_core_cells, 0.0, 4.0)) {
    err << "warp.layered.face_core must be in [0, 4] cells (0 = off), got "
        << o.face_core_cells;
  } else if (!in(o.offset_lowpass_hz, 0.0, 10.0)) {
    err << "warp.layered.offset_lowpass_hz must be in [0, 10] Hz (0 = off), "
           "got "
        << o.offset_lowpass_hz;
  } else if (!in(o.min_cell_ratio, 0.0, 0.99)) {
    err << "warp.layered.min_cell_ratio must be in [0, 0.99] (0 = off), got "
        << o.min_cell_ratio;
  } else if (!in(o.band_data_weight, 1e-6, 1.0) ||
             !in(o.shape_weight, 0.0, 1e4) ||
             !in(o.temporal_weight, 0.0, 1e4)) {
    err << "warp.layered: band_data_weight must be in (0, 1], shape_weight and "
           "temporal_weight in [0, 1e4]";
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

LayerBlend::LayerBlend(const std::vector<double>& u,
                       const std::vector<double>& v,
                       const LayerBlendOptions& options)
    : cols_(static_cast<int>(u.size())),
      rows_(static_cast<int>(v.size())),
      u_(u),
      v_(v),
      options_(options),
      offset_lowpass_(options.offset_lowpass_hz > 0.0 ? options.offset_lowpass_hz : 1.0) {
  const int n = cols_ * rows_;
  double du = 0.0, dv = 0.0;
  for (int i = 0; i + 1 < cols_; ++i) du = std::max(du, u_[i + 1] - u_[i]);
  for (int j = 0; j + 1 < rows_; ++j) dv = std::max(dv, v_[j + 1] - v_[j]);
  cell_diagonal_ = std::hypot(du, dv);
  std::vector<Eigen::Triplet<double>> s;
  int row = 0;
  auto id = [this](int i, int j) { return j * cols_ + i; };
  for (int j = 0; j + 1 < rows_; ++j) {
    for (int i = 0; i + 1 < cols_; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1),
                e = id(i, j + 1);
      for (const Triangle& t : {Triangle{a, b, e}, Triangle{b, c, a},
                                Triangle{c, e, b}, Triangle{e, a, c}}) {
        auto pos = [this](int k) {
          return Eigen::Vector2d(u_[k % cols_], v_[k / cols_]);
        };
        // V1 - V2 = p (V3 - V2) + q R90 (V3 - V2), R90 (x, y) = (y, -x).
        const Eigen::Vector2d ed = pos(t.v3) - pos(t.v2);
        Eigen::Matrix2d E;
        E << ed.x(), ed.y(), ed.y(), -ed.x();
        const Eigen::Vector2d pq = E.inverse() * (pos(t.v1) - pos(t.v2));
        const double p = pq.x(), q = pq.y();
        // r_x = d1x - d2x - p (d3x - d2x) - q (d3y - d2y)
        // r_y = d1y - d2y - p (d3y - d2y) + q (d3x - d2x)
        auto add = [&s](int r, int k, double c0) { s.emplace_back(r, k, c0); };
        add(row, 2 * t.v1, 1.0);
        add(row, 2 * t.v2, -1.0 + p);
        add(row, 2 * t.v3, -p);
        add(row, 2 * t.v2 + 1, q);
        add(row, 2 * t.v3 + 1, -q);
        add(row + 1, 2 * t.v1 + 1, 1.0);
        add(row + 1, 2 * t.v2 + 1, -1.0 + p);
        add(row + 1, 2 * t.v3 + 1, -p);
        add(row + 1, 2 * t.v2, -q);
        add(row + 1, 2 * t.v3, q);
        row += 2;
      }
    }
  }
  Eigen::SparseMatrix<double> S(std::max(row, 1), 2 * n);
  S.setFromTriplets(s.begin(), s.end());
  shape_ =
      options_.shape_weight * Eigen::SparseMatrix<double>(S.transpose() * S);
  shape_.makeCompressed();
  d_previous_ = Eigen::VectorXd::Zero(2 * n);
  e_previous_ = Eigen::VectorXd::Zero(2 * n);
  alpha_.assign(n, 0.0);
}

void LayerBlend::Blend(const std::vector<Eigen::Vector2f>& subject,
                       const std::vector<Eigen::Vector2f>& background,
                       const SubjectRegion& region, double dt, int input_width,
                       int input_height, std::vector<Eigen::Vector2f>* source,
                       LayerBlendReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const int n = cols_ * rows_;
  LayerBlendReport r;
  r.blend = region.valid ? region.blend : 0.0;
  source->resize(n);
  if (!region.valid || region.blend <= 0.0) {
    *source = background;
    alpha_.assign(n, 0.0);
    d_previous_.setZero();
    e_previous_.setZero();
    has_previous_ = true;
    offset_lowpass_.Reset();
    r.solve_ms = 0.0;
    // The background layer's own cells (one global warp).
    MeasureCells(*source, &r);
    *report = r;
    return;
  }
  r.layered = true;
  const double in_per_out = InputPerOutput(background);
  std::vector<bool> free_vertex;
  BandWeights(region, &free_vertex, &r);
  Eigen::Vector2d shift, fast;
  const double cap = SplitHeadOffset(subject, background, region, dt, in_per_out, &shift,
                                     &fast, &r);
  // Targets T_k. Vertices in the core and beyond the band are held at
  // their targets (their data terms dominate: they follow their layer);
  // only the band's vertices are unknowns of the least-squares problem.
  Eigen::VectorXd target(2 * n);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d D = (subject[k] - background[k]).cast<double>();
    target.segment<2>(2 * k) = shift + alpha_[k] * cap * (D - smooth_);
  }
  Eigen::VectorXd d = SolveBand(target, free_vertex);
  // The pulls below scale d's departure from the layer that does not give
  // way: d_k = base_k + s (d_k - base_k), with base 0 (the background
  // layer) or, yielding to the subject, g D_k (the background layer moved
  // g of the way to the subject layer; with both layers inside the frame,
  // so is every convex mix of them). At s = 0 the mesh is that layer's.
  Eigen::VectorXd base = Eigen::VectorXd::Zero(2 * n);
  if (options_.yield_to_subject) {
    for (int k = 0; k < n; ++k) {
      base.segment<2>(2 * k) = region.blend * (subject[k] - background[k]).cast<double>();
    }
  }
  // The base mesh's vertices and how far each lies outside the input frame
  // (the pulls and the final clamp allow a vertex that much).
  const double w1 = input_width - 1.0, h1 = input_height - 1.0;
  std::vector<Eigen::Vector2d> base_mesh(n);
  std::vector<double> base_excess(n);
  for (int k = 0; k < n; ++k) {
    base_mesh[k] = background[k].cast<double>() + base.segment<2>(2 * k);
    base_excess[k] = Excess(base_mesh[k], w1, h1);
  }
  Eigen::VectorXd departure = d - base;
  r.protrusion_keep = PullInsideFrame(base_mesh, base_excess, w1, h1, &departure);
  if (r.protrusion_keep < 1.0) d = base + departure;
  if (options_.min_cell_ratio > 0.0) {
    const double keep = PullUnsqueezed(base_mesh, departure);
    if (keep < 1.0) {
      r.distortion_keep = keep;
      d = base + keep * departure;
    }
  }
  WriteMesh(background, region, d, base_excess, w1, h1, source, &r);
  e_previous_ = d - target;
  // Distortion of the result.
  MeasureCells(*source, &r);
  std::vector<double> added;
  CellRatios(cols_, rows_, u_, v_, *source, &background, &added);
  if (!added.empty()) r.min_added_ratio = *std::min_element(added.begin(), added.end());
  r.solve_ms = MsSince(start);
  *report = r;
}

double LayerBlend::InputPerOutput(const std::vector<Eigen::Vector2f>& background) const {
  // Output px per input px, from the background mesh's middle row.
  const int j = rows_ / 2;
  double sum = 0.0, span = 0.0;
  for (int i = 0; i + 1 < cols_; ++i) {
    sum += (background[j * cols_ + i + 1] - background[j * cols_ + i]).cast<double>().norm();
    span += u_[i + 1] - u_[i];
  }
  return span > 0 ? sum / span : 1.0;
}

void LayerBlend::BandWeights(const SubjectRegion& region, std::vector<bool>* free_vertex,
                             LayerBlendReport* r) {
  // The band runs from band_inside * B inside the outline to the rest of B
  // outside it, moved outline_margin_cells cell diagonals further in.
  const int n = cols_ * rows_;
  const double B = std::max(1.0, options_.band_width * region.jaw_width);
  const double outer =
      (1.0 - options_.band_inside) * B - options_.outline_margin_cells * cell_diagonal_;
  r->band_px = B;
  r->band_outer_px = outer;
  region.GridDistances(u_, v_, &distance_);
  FaceCoreWeights(region);
  firm_.assign(n, 0.0);
  free_vertex->assign(n, false);
  double room = B;  // from the face's core to the band's outer edge
  for (int k = 0; k < n; ++k) {
    const double inside = outer - distance_[k];
    const double s = std::min(1.0, std::max(0.0, inside / B));
    alpha_[k] = region.blend * s * s * (3.0 - 2.0 * s);
    // The face's core bounds the room the band has (a vertex's bound
    // loosens by a cell diagonal as its core weight falls to 0, so the room
    // moves continuously with the face), and pulls only inside the band's
    // outer edge, fading in over a quarter cell diagonal from it (beyond it
    // every vertex stays on the background layer).
    if (core_[k] > 0.0) room = std::min(room, inside + (1.0 - core_[k]) * cell_diagonal_);
    core_[k] *= std::min(1.0, std::max(0.0, inside / (kCoreFade * cell_diagonal_)));
    alpha_[k] = std::max(alpha_[k], region.blend * core_[k]);
    (*free_vertex)[k] = s > 0.0 && s < 1.0;
    // Firm near the band's edges: a vertex that crosses an edge (held on
    // one side, free on the other) keeps its place, instead of jumping by
    // whatever the shape term gives a barely held vertex.
    const double edge = std::max(0.0, 1.0 - std::min(s, 1.0 - s) / kFirmEdge);
    firm_[k] = std::max(core_[k], edge);
  }
  r->room_px = std::max(1.0, std::min(B, room));
  r->reach_px = options_.max_offset * r->room_px;
}

void LayerBlend::FaceCoreWeights(const SubjectRegion& region) {
  // 1 within face_core_cells cells (per axis) of the landmark centre, fading
  // linearly to 0 one cell further out: every vertex of the cell under the
  // centre gets 1, and the weights move continuously with the face.
  const int n = cols_ * rows_;
  core_.assign(n, 0.0);
  const double c = options_.face_core_cells;
  if (c <= 0.0 || !region.face_centre.allFinite()) return;
  const Eigen::Vector2d& f = region.face_centre;
  for (int k = 0; k < n; ++k) {
    const int i = k % cols_, j = k / cols_;
    // The cell size around vertex k (the mean of its two neighbouring cells).
    const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, cols_ - 1);
    const int j0 = std::max(j - 1, 0), j1 = std::min(j + 1, rows_ - 1);
    const double cu = (u_[i1] - u_[i0]) / std::max(1, i1 - i0);
    const double cv = (v_[j1] - v_[j0]) / std::max(1, j1 - j0);
    const double wx = std::min(1.0, std::max(0.0, 1.0 + c - std::abs(u_[i] - f.x()) / cu));
    const double wy = std::min(1.0, std::max(0.0, 1.0 + c - std::abs(v_[j] - f.y()) / cv));
    core_[k] = wx * wy;
  }
}

Eigen::Vector2d LayerBlend::OffsetAt(const std::vector<Eigen::Vector2f>& subject,
                                     const std::vector<Eigen::Vector2f>& background,
                                     const Eigen::Vector2d& h) const {
  // Bilinear in the vertex grid.
  int i = 0, j = 0;
  while (i + 2 < cols_ && u_[i + 1] < h.x()) ++i;
  while (j + 2 < rows_ && v_[j + 1] < h.y()) ++j;
  const double a = std::min(1.0, std::max(0.0, (h.x() - u_[i]) / (u_[i + 1] - u_[i])));
  const double b = std::min(1.0, std::max(0.0, (h.y() - v_[j]) / (v_[j + 1] - v_[j])));
  auto D = [&](int ii, int jj) {
    const int k = jj * cols_ + ii;
    return (subject[k] - background[k]).cast<double>().eval();
  };
  return (1 - a) * (1 - b) * D(i, j) + a * (1 - b) * D(i + 1, j) + (1 - a) * b * D(i, j + 1) +
         a * b * D(i + 1, j + 1);
}

double LayerBlend::SplitHeadOffset(const std::vector<Eigen::Vector2f>& subject,
                                   const std::vector<Eigen::Vector2f>& background,
                                   const SubjectRegion& region, double dt, double in_per_out,
                                   Eigen::Vector2d* shift, Eigen::Vector2d* fast,
                                   LayerBlendReport* r) {
  const Eigen::Vector2d Dc = OffsetAt(subject, background, region.head_centre);
  // The slow part of the offset moves the whole frame (a type-2 tracking
  // loop: no lag on ramps such as a pan); the band absorbs the rest.
  if (options_.offset_lowpass_hz <= 0.0) {
    smooth_.setZero();
  } else {
    smooth_ = offset_lowpass_.Update(Dc, dt);
  }
  *shift = region.blend * smooth_;
  *fast = Dc - smooth_;
  r->offset_px = region.blend * fast->norm() / in_per_out;
  double cap = 1.0;
  const double max_offset_px = r->reach_px;
  if (max_offset_px > 0 && r->offset_px > max_offset_px) cap = max_offset_px / r->offset_px;
  r->capped_offset_px = r->offset_px * cap;
  // Yielding to the subject, what the cap takes from the band moves the
  // whole frame instead: the core still follows the subject layer.
  if (options_.yield_to_subject) *shift += region.blend * (1.0 - cap) * *fast;
  r->shift_px = shift->norm() / in_per_out;
  return cap;
}

Eigen::VectorXd LayerBlend::SolveBand(const Eigen::VectorXd& target,
                                      const std::vector<bool>& free_vertex) {
  // Fixed vertices enter the right-hand side through the shape term.
  const int n = cols_ * rows_;
  const double wt = has_previous_ ? options_.temporal_weight : 0.0;
  Eigen::VectorXd d = target;
  free_.assign(2 * n, -1);
  int m = 0;
  for (int k = 0; k < n; ++k) {
    if (free_vertex[k]) {
      free_[2 * k] = m++;
      free_[2 * k + 1] = m++;
    }
  }
  if (m == 0) return d;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m);
  triplets_.clear();
  for (int col = 0; col < shape_.outerSize(); ++col) {
    const int fc = free_[col];
    for (Eigen::SparseMatrix<double>::InnerIterator it(shape_, col); it; ++it) {
      const int fr = free_[it.row()];
      if (fr < 0) continue;
      if (fc >= 0) {
        triplets_.emplace_back(fr, fc, it.value());
      } else {
        rhs(fr) -= it.value() * target(col);  // a held neighbour
      }
    }
  }
  for (int q = 0; q < 2 * n; ++q) {
    const int f = free_[q];
    if (f < 0) continue;
    // Temporal: the correction d - T changes slowly (not d itself, which
    // must follow the subject without lag).
    // The face's core (FaceCoreWeights) and the band's edges are pulled to
    // their targets as firmly as held vertices; the band's middle only
    // weakly (there the shape term decides).
    const double firm = kFirmWeight * std::max(1.0, options_.shape_weight) * firm_[q / 2];
    const double wd = options_.band_data_weight + firm;
    triplets_.emplace_back(f, f, wd + wt);
    rhs(f) += wd * target(q) + wt * (target(q) + e_previous_(q));
  }
  system_.resize(m, m);
  system_.setFromTriplets(triplets_.begin(), triplets_.end());
  solver_.compute(system_);
  const Eigen::VectorXd x = solver_.solve(rhs);
  if (solver_.info() == Eigen::Success && x.allFinite()) {
    for (int q = 0; q < 2 * n; ++q) {
      if (free_[q] >= 0) d(q) = x(free_[q]);
    }
  }  // else (cannot happen for this SPD system) the plain blend T stays
  return d;
}

double LayerBlend::PullInsideFrame(const std::vector<Eigen::Vector2d>& base_mesh,
                                   const std::vector<double>& base_excess, double w1, double h1,
                                   Eigen::VectorXd* departure) const {
  // No undefined pixels: scale the departure towards the base if a vertex
  // leaves the input frame (more than the base's own vertex does).
  const int n = cols_ * rows_;
  auto feasible = [&](double s) {
    for (int k = 0; k < n; ++k) {
      if (Excess(base_mesh[k] + s * departure->segment<2>(2 * k), w1, h1) >
          base_excess[k] + 1e-3)
        return false;
    }
    return true;
  };
  if (feasible(1.0)) return 1.0;
  double lo = 0.0, hi = 1.0;
  for (int it = 0; it < 12; ++it) {
    const double mid = 0.5 * (lo + hi);
    (feasible(mid) ? lo : hi) = mid;
  }
  *departure *= lo;
  return lo;
}

double LayerBlend::PullUnsqueezed(const std::vector<Eigen::Vector2d>& base_mesh,
                                  const Eigen::VectorXd& departure) const {
  // No squeezed cell: the largest scale of the departure at which no cell's
  // ratio is below the floor (or below the base's own ratio for that cell,
  // where that is lower already). At scale 0 every cell is the base's, so
  // the bisection's lower end is always allowed.
  const int n = cols_ * rows_;
  std::vector<Eigen::Vector2f> scaled(n);
  for (int k = 0; k < n; ++k) scaled[k] = base_mesh[k].cast<float>();
  std::vector<double> floor_ratio;
  CellRatios(cols_, rows_, u_, v_, scaled, nullptr, &floor_ratio);
  for (double& q : floor_ratio) q = std::min(q, options_.min_cell_ratio);
  std::vector<double> ratios;
  auto unsqueezed = [&](double s) {
    for (int k = 0; k < n; ++k) {
      scaled[k] = (base_mesh[k] + s * departure.segment<2>(2 * k)).cast<float>();
    }
    CellRatios(cols_, rows_, u_, v_, scaled, nullptr, &ratios);
    for (size_t q = 0; q < ratios.size(); ++q) {
      if (ratios[q] < floor_ratio[q] - 1e-4) return false;
    }
    return true;
  };
  if (unsqueezed(1.0)) return 1.0;
  double lo = 0.0, hi = 1.0;
  for (int it = 0; it < 12; ++it) {
    const double mid = 0.5 * (lo + hi);
    (unsqueezed(mid) ? lo : hi) = mid;
  }
  return lo;
}

void LayerBlend::WriteMesh(const std::vector<Eigen::Vector2f>& background,
                           const SubjectRegion& region, const Eigen::VectorXd& d,
                           const std::vector<double>& base_excess, double w1, double h1,
                           std::vector<Eigen::Vector2f>* source, LayerBlendReport* r) {
  // Band vertex flicker, then the final mesh.
  const int n = cols_ * rows_;
  double step2 = 0.0;
  int band = 0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d dk = d.segment<2>(2 * k);
    if (alpha_[k] > 0.0 && alpha_[k] < region.blend && has_previous_) {
      step2 += (dk - d_previous_.segment<2>(2 * k)).squaredNorm();
      ++band;
    }
    // Clamp to the frame (or to the base vertex's own excursion): removes
    // rounding, never moves a vertex by more than ~1e-3 px.
    const double ex = base_excess[k];
    const Eigen::Vector2d q = (background[k].cast<double>() + dk)
                                  .cwiseMax(Eigen::Vector2d::Constant(-ex))
                                  .cwiseMin(Eigen::Vector2d(w1 + ex, h1 + ex));
    (*source)[k] = q.cast<float>();
  }
  r->band_vertex_step_px = band > 0 ? std::sqrt(step2 / band) : 0.0;
  d_previous_ = d;
  has_previous_ = true;
}

void LayerBlend::MeasureCells(const std::vector<Eigen::Vector2f>& source,
                              LayerBlendReport* r) {
  r->folded_cells =
      CellRatios(cols_, rows_, u_, v_, source, nullptr, &ratios_scratch_);
  if (ratios_scratch_.empty()) return;
  std::vector<double> sorted = ratios_scratch_;
  std::sort(sorted.begin(), sorted.end());
  r->min_cell_ratio = sorted.front();
  r->p01_cell_ratio = sorted[static_cast<size_t>(0.01 * (sorted.size() - 1))];
}

int CellRatios(int cols, int rows, const std::vector<double>& u,
               const std::vector<double>& v,
               const std::vector<Eigen::Vector2f>& source,
               const std::vector<Eigen::Vector2f>* reference,
               std::vector<double>* ratio) {
  ratio->clear();
  int folded = 0;
  auto jac = [&](const std::vector<Eigen::Vector2f>& m, int i, int j,
                 Eigen::Matrix2d* J, bool* flipped) {
    const Eigen::Vector2d a = m[j * cols + i].cast<double>();
    const Eigen::Vector2d b = m[j * cols + i + 1].cast<double>();
    const Eigen::Vector2d c = m[(j + 1) * cols + i + 1].cast<double>();
    const Eigen::Vector2d e = m[(j + 1) * cols + i].cast<double>();
    const double du = u[i + 1] - u[i], dv = v[j + 1] - v[j];
    J->col(0) = ((b - a) + (c - e)) / (2.0 * du);
    J->col(1) = ((e - a) + (c - b)) / (2.0 * dv);
    *flipped = Cross(b - a, e - a) <= 0 || Cross(c - b, a - b) <= 0 ||
               Cross(e - c, b - c) <= 0 || Cross(a - e, c - e) <= 0;
  };
  for (int j = 0; j + 1 < rows; ++j) {
    for (int i = 0; i + 1 < cols; ++i) {
      Eigen::Matrix2d J;
      bool flipped = false;
      jac(source, i, j, &J, &flipped);
      if (flipped) ++folded;
      if (reference != nullptr) {
        Eigen::Matrix2d R;
        bool ref_flipped = false;
        jac(*reference, i, j, &R, &ref_flipped);
        if (std::abs(R.determinant()) > 1e-12) J = J * R.inverse();
      }
      ratio->push_back(flipped ? 0.0 : SingularRatio(J));
    }
  }
  return folded;
}

}  // namespace steadiface
