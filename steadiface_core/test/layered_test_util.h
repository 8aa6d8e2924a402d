#pragma once
// Meshes and subject regions with known geometry, for the layered warp's
// tests (layer_blend_test.cc, subject_region_test.cc).

#include <array>
#include <vector>

#include <Eigen/Core>

#include "steadiface_core/layered/layer_blend.h"
#include "steadiface_core/layered/subject_region.h"

namespace steadiface {
namespace testing_util {

// A 33 x 19 vertex grid over a 640 x 360 output.
struct Grid {
  std::vector<double> u, v;
  Grid() {
    for (int i = 0; i <= 32; ++i) u.push_back(i * 639.0 / 32);
    for (int j = 0; j <= 18; ++j) v.push_back(j * 359.0 / 18);
  }
  int n() const { return static_cast<int>(u.size() * v.size()); }
  Eigen::Vector2d At(int k) const {
    return Eigen::Vector2d(u[k % u.size()], v[k / u.size()]);
  }
  // The background layer: the output shifted into an 840 x 460 input.
  std::vector<Eigen::Vector2f> Background() const {
    std::vector<Eigen::Vector2f> b(n());
    for (int k = 0; k < n(); ++k)
      b[k] = (At(k) + Eigen::Vector2d(100, 50)).cast<float>();
    return b;
  }
};

// A head of jaw width 100 px centred at (320, 150), shoulders below.
inline SubjectRegion Region(double blend = 1.0) {
  SubjectRegion r;
  r.valid = true;
  r.jaw_width = 100;
  r.face_height = 90;
  r.chin = Eigen::Vector2d(320, 215);
  r.head_centre = Eigen::Vector2d(320, 150);
  r.head_axes = Eigen::Vector2d(70, 75);
  r.torso = true;
  r.neck_half_width = 35;
  r.shoulder_axes = Eigen::Vector2d(150, 180);
  r.shoulder_centre = r.chin + Eigen::Vector2d(0, 0.6 * 90 + 180);
  r.blend = blend;
  return r;
}

// Region() scaled to a jaw of `jaw` px about its head centre, with the
// landmark centre 0.3 jaw widths below the head ellipse's centre.
inline SubjectRegion Head(double jaw) {
  SubjectRegion r = Region();
  const double k = jaw / r.jaw_width;
  auto scale = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(r.head_centre + k * (p - r.head_centre));
  };
  r.chin = scale(r.chin);
  r.shoulder_centre = scale(r.shoulder_centre);
  r.jaw_width *= k;
  r.face_height *= k;
  r.head_axes *= k;
  r.neck_half_width *= k;
  r.shoulder_axes *= k;
  r.face_centre = r.head_centre + Eigen::Vector2d(0.0, 0.3 * jaw);
  return r;
}

// A band that straddles the outline, a whole-frame shift for the offset's
// slow part and the face first where the layers cannot be joined: the
// mechanisms the default (a band inside the subject that never bends the
// background) switches off, still options.
inline LayerBlendOptions Straddling() {
  LayerBlendOptions o;
  o.band_width = 0.5;
  o.band_inside = 0.5;
  o.outline_margin_cells = 0.0;
  o.offset_lowpass_hz = 0.1;
  o.yield_to_subject = true;
  return o;
}

inline LayerBlendOptions NoSlowShift() {
  LayerBlendOptions o = Straddling();
  o.offset_lowpass_hz = 0.0;  // the band absorbs the whole offset
  return o;
}

// The background-first variant (the subject gives way).
inline LayerBlendOptions YieldingToTheBackground(LayerBlendOptions o) {
  o.yield_to_subject = false;
  return o;
}

inline std::vector<Eigen::Vector2f> Shifted(const std::vector<Eigen::Vector2f>& b,
                                     const Eigen::Vector2d& T) {
  std::vector<Eigen::Vector2f> s = b;
  for (auto& p : s) p += T.cast<float>();
  return s;
}

// The joined mesh's offset from the background layer at output point p
// (bilinear in its cell, as the sampler interpolates).
inline Eigen::Vector2d OffsetAt(const Grid& g, const std::vector<Eigen::Vector2f>& out,
                         const std::vector<Eigen::Vector2f>& background, const Eigen::Vector2d& p) {
  const int cols = static_cast<int>(g.u.size());
  int i = 0, j = 0;
  while (i + 2 < cols && g.u[i + 1] <= p.x()) ++i;
  while (j + 2 < static_cast<int>(g.v.size()) && g.v[j + 1] <= p.y()) ++j;
  const double a = (p.x() - g.u[i]) / (g.u[i + 1] - g.u[i]);
  const double b = (p.y() - g.v[j]) / (g.v[j + 1] - g.v[j]);
  auto d = [&](int ii, int jj) {
    const int k = jj * cols + ii;
    return (out[k] - background[k]).cast<double>().eval();
  };
  return (1 - a) * (1 - b) * d(i, j) + a * (1 - b) * d(i + 1, j) + (1 - a) * b * d(i, j + 1) +
         a * b * d(i + 1, j + 1);
}

// The mesh cells (their four vertex indices) that reach outside the
// region's outline.
inline std::vector<std::array<int, 4>> CellsReachingOut(const Grid& g,
                                                       const SubjectRegion& region) {
  std::vector<std::array<int, 4>> cells;
  const int cols = static_cast<int>(g.u.size());
  for (int j = 0; j + 1 < static_cast<int>(g.v.size()); ++j) {
    for (int i = 0; i + 1 < cols; ++i) {
      const std::array<int, 4> c = {j * cols + i, j * cols + i + 1, (j + 1) * cols + i,
                                    (j + 1) * cols + i + 1};
      bool reaches_out = false;
      for (int k : c) reaches_out = reaches_out || region.SignedDistance(g.At(k)) > 0.0;
      if (reaches_out) cells.push_back(c);
    }
  }
  return cells;
}

// True when every cell that reaches outside the region's outline keeps all
// four vertices exactly on the background layer.
inline bool BackgroundUnbent(const Grid& g, const SubjectRegion& region,
                             const std::vector<Eigen::Vector2f>& out,
                             const std::vector<Eigen::Vector2f>& background) {
  for (const auto& c : CellsReachingOut(g, region)) {
    for (int k : c) {
      if (out[k] != background[k]) return false;
    }
  }
  return true;
}


}  // namespace testing_util
}  // namespace steadiface
