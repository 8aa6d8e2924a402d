// The mesh optimization that joins the layered warp's two layers
// (LayerBlend), piece by piece against closed forms, on meshes whose layers
// differ by a known translation: the band, the cap, the pulls, the face's
// core and continuity as the face moves.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "layered_test_util.h"
#include "steadiface_core/layered/layer_blend.h"
#include "steadiface_core/layered/subject_region.h"

namespace steadiface {
namespace {

using testing_util::BackgroundUnbent;
using testing_util::Grid;
using testing_util::Head;
using testing_util::NoSlowShift;
using testing_util::OffsetAt;
using testing_util::Region;
using testing_util::Shifted;
using testing_util::Straddling;
using testing_util::YieldingToTheBackground;

// Layers that differ by a translation T: the core moves by T, the
// background beyond the band not at all, the band in between, with no
// fold-over and the stretch the band width implies.
TEST(LayerBlendTest, CoreFollowsTheSubjectLayerAndTheBackgroundStaysPut) {
  const Grid g;
  const auto background = g.Background();
  const Eigen::Vector2d T(8.0, -5.0);
  LayerBlend blend(g.u, g.v, NoSlowShift());
  std::vector<Eigen::Vector2f> out;
  LayerBlendReport rep;
  const SubjectRegion region = Region();
  blend.Blend(Shifted(background, T), background, region, 0.0, 840, 460, &out,
              &rep);
  ASSERT_TRUE(rep.layered);
  const double B = 0.5 * 100, outer = 0.5 * B;
  EXPECT_DOUBLE_EQ(rep.band_px, B);
  // The core follows the subject layer and the rest the background layer
  // exactly (float rounding only); the band's vertices lie in between.
  int core = 0, far = 0;
  for (int k = 0; k < g.n(); ++k) {
    const Eigen::Vector2d d = (out[k] - background[k]).cast<double>();
    const double dist = region.SignedDistance(g.At(k));
    if (dist <= outer - B) {
      EXPECT_LT((d - T).norm(), 1e-3) << "core vertex " << k;
      ++core;
    } else if (dist >= outer) {
      EXPECT_LT(d.norm(), 1e-3) << "background vertex " << k;
      ++far;
    } else {
      EXPECT_LE(d.norm(), 1.02 * T.norm()) << "band vertex " << k;
    }
  }
  EXPECT_GT(core, 20);
  EXPECT_GT(far, 200);
  EXPECT_EQ(rep.folded_cells, 0);
  // A translation |T| spread over B stretches by ~1.5 |T| / B at most.
  EXPECT_GT(rep.min_cell_ratio, 1.0 - 2.0 * 1.5 * T.norm() / B);
  EXPECT_LT(rep.min_cell_ratio, 0.995);  // the band does bend
  EXPECT_NEAR(rep.offset_px, T.norm(), 0.05);
  EXPECT_DOUBLE_EQ(rep.protrusion_keep, 1.0);
}

// The defaults never bend the background: every cell that reaches outside
// the subject's outline (where the background shows) keeps all four
// vertices exactly on the background layer, while the head's core follows
// the subject layer, and the band inside the outline absorbs an offset of
// band width x max_offset without squeezing a cell below 0.5.
TEST(LayerBlendTest, TheDefaultBandNeverBendsTheBackground) {
  const Grid g;
  const auto background = g.Background();
  const LayerBlendOptions o;
  const SubjectRegion region = Region();
  const double reach = o.band_width * o.max_offset * region.jaw_width;  // 12.25 px
  for (const Eigen::Vector2d& T : {Eigen::Vector2d(reach, 0.0), Eigen::Vector2d(0.0, -reach),
                                   Eigen::Vector2d(0.7 * reach, 0.7 * reach)}) {
    LayerBlend blend(g.u, g.v, o);
    std::vector<Eigen::Vector2f> out;
    LayerBlendReport rep;
    blend.Blend(Shifted(background, T), background, region, 0.0, 840, 460, &out, &rep);
    ASSERT_TRUE(rep.layered);
    const auto outside = CellsReachingOut(g, region);
    for (const auto& c : outside) {
      for (int k : c) {
        EXPECT_EQ(out[k], background[k]) << "vertex " << k << " of a cell reaching the background";
      }
    }
    EXPECT_GT(outside.size(), 400u);
    // The core: deeper inside than the band and the margin (a cell
    // diagonal, 28.2 px here). On this small head (jaw 100 px on a 20 px
    // grid) that leaves a core of ~7 px: 5 vertices, in the shoulders.
    const double inner = -(o.band_width * region.jaw_width +
                           o.outline_margin_cells * std::hypot(g.u[1] - g.u[0], g.v[1] - g.v[0]));
    int core = 0;
    for (int k = 0; k < g.n(); ++k) {
      if (region.SignedDistance(g.At(k)) > inner) continue;
      EXPECT_LT(((out[k] - background[k]).cast<double>() - T).norm(), 1e-3) << "core vertex " << k;
      ++core;
    }
    EXPECT_GE(core, 5);
    EXPECT_EQ(rep.folded_cells, 0);
    EXPECT_GE(rep.min_cell_ratio, 0.5);
    EXPECT_DOUBLE_EQ(rep.distortion_keep, 1.0);
    EXPECT_DOUBLE_EQ(rep.shift_px, 0.0);  // nothing moves the whole frame
  }
}

// The face's own cell follows the subject layer (face_core_cells). The
// band alone leaves a head that is small for the mesh no core at its
// landmark centre, 0.3 jaw widths below the head ellipse's centre: the centre
// keeps 6-72 % of the layers' offset (jaw 100-200 px on 20 px cells). With
// the face core, from a jaw of 7.5 cells (150 px here) up, the centre moves
// with the subject layer by the whole offset wherever it lies in its cell,
// up to the reach the report states; the background is never bent, and the
// cap keeps every cell at 0.5 or more without a pull. The reach is what the
// room between the core and the band's outer edge allows: a few px where
// the core nears the neck (jaw 150, low in its cell), the full band width x
// cap on a large face. A smaller face keeps more of the offset than without
// the core, but not all of it: its core runs into the band's outer edge.
TEST(LayerBlendTest, TheFaceCentreFollowsTheSubjectLayerWhereverItLiesInItsCell) {
  const Grid g;
  const auto background = g.Background();
  const LayerBlendOptions o;
  LayerBlendOptions off;
  off.face_core_cells = 0.0;
  for (double jaw : {100.0, 130.0, 150.0, 200.0, 260.0}) {
    const bool exact = jaw >= 150.0;
    double least_with = 1.0, least_without = 1.0, least_reach = 1e9;
    for (double a : {0.0, 0.3, 0.5, 0.8}) {
      for (double b : {0.0, 0.4, 0.7}) {
        SubjectRegion region = Head(jaw);
        region.face_centre += Eigen::Vector2d(a * 20.0, b * 20.0);
        for (const Eigen::Vector2d& dir : {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, -1),
                                           Eigen::Vector2d(-0.6, 0.8)}) {
          LayerBlend probe(g.u, g.v, o);
          std::vector<Eigen::Vector2f> out;
          LayerBlendReport rep;
          probe.Blend(Shifted(background, dir), background, region, 0.0, 840, 460, &out, &rep);
          least_reach = std::min(least_reach, rep.reach_px);
          const Eigen::Vector2d T = 0.95 * rep.reach_px * dir;
          LayerBlend with(g.u, g.v, o), without(g.u, g.v, off);
          with.Blend(Shifted(background, T), background, region, 0.0, 840, 460, &out, &rep);
          const Eigen::Vector2d kept = OffsetAt(g, out, background, region.face_centre);
          least_with = std::min(least_with, kept.dot(T) / T.squaredNorm());
          if (exact) {
            EXPECT_LT((kept - T).norm(), 0.02 * T.norm())
                << "jaw " << jaw << ", face centre " << region.face_centre.transpose()
                << ", offset " << T.transpose();
          }
          EXPECT_TRUE(BackgroundUnbent(g, region, out, background));
          EXPECT_EQ(rep.folded_cells, 0);
          EXPECT_GE(rep.min_cell_ratio, 0.5);
          EXPECT_DOUBLE_EQ(rep.distortion_keep, 1.0);
          EXPECT_NEAR(rep.capped_offset_px, T.norm(), 1e-3);  // below the cap (float mesh)
          without.Blend(Shifted(background, T), background, region, 0.0, 840, 460, &out, &rep);
          const Eigen::Vector2d kept_without = OffsetAt(g, out, background, region.face_centre);
          least_without = std::min(least_without, kept_without.dot(T) / T.squaredNorm());
        }
      }
    }
    std::printf("  jaw %.0f px: reach >= %.1f px; the face centre keeps >= %.2f of the offset with "
                "the face core, %.2f without\n",
                jaw, least_reach, least_with, least_without);
    EXPECT_GE(least_with, least_without - 0.01) << "jaw " << jaw;  // never worse
    if (jaw <= 200.0) EXPECT_GT(least_with, least_without + 0.2) << "jaw " << jaw;
    if (exact) EXPECT_GT(least_reach, jaw >= 200.0 ? 5.0 : 1.0) << "jaw " << jaw;
  }
}

// The largest per-step change of any vertex of the joined mesh while the
// region (landmark centre at (320, 180) + step (1, 0.5) px) crosses two
// cells, the layers' offset T fixed [px].
double WorstVertexStep(const LayerBlendOptions& o, const Eigen::Vector2d& T) {
  const Grid g;
  const auto background = g.Background();
  LayerBlend blend(g.u, g.v, o);
  std::vector<Eigen::Vector2f> out, previous;
  LayerBlendReport rep;
  double worst = 0.0;
  for (int step = 0; step <= 40; ++step) {
    SubjectRegion region = Region();
    const Eigen::Vector2d move(step * 1.0, step * 0.5);
    region.head_centre += move;
    region.chin += move;
    region.shoulder_centre += move;
    region.face_centre = Eigen::Vector2d(320.0, 180.0) + move;
    blend.Blend(Shifted(background, T), background, region, 1.0 / 30.0, 840, 460, &out, &rep);
    for (size_t k = 0; k < previous.size(); ++k) {
      worst = std::max(worst, static_cast<double>((out[k] - previous[k]).norm()));
    }
    previous = out;
  }
  return worst;
}

// The band and the face core move with the face without jumps: as the
// region crosses two cells in 1 px steps, the layers' offset fixed, every
// vertex's offset changes by a small fraction of the offset per step. (Before
// the band's edges were firm, a vertex crossing one stepped by the whole
// offset, 9.8 px, here.)
TEST(LayerBlendTest, TheFaceCoreMovesWithTheFaceWithoutJumps) {
  const Eigen::Vector2d T(9.0, -4.0);
  LayerBlendOptions without_core;
  without_core.face_core_cells = 0.0;
  const double with = WorstVertexStep(LayerBlendOptions(), T);
  const double without = WorstVertexStep(without_core, T);
  std::printf("  largest vertex step per 1 px of face motion: %.3f px with the face core, %.3f px "
              "without (offset %.1f px)\n",
              with, without, T.norm());
  // The profile slides with the face by ~|T| / band width per px; a vertex
  // that switched between held and free would step by much of |T|. (Without
  // the face core the cap does not engage here and the band's inner edge,
  // under the chin, steps by up to a quarter of |T|.)
  EXPECT_LT(with, 0.06 * T.norm());
  EXPECT_LT(without, 0.25 * T.norm());
}

// The similarity term is what tames the bending: the optimized band is less
// distorted than the plain per-vertex blend it starts from.
TEST(LayerBlendTest, TheShapeTermDistortsLessThanThePlainBlend) {
  const Grid g;
  const auto background = g.Background();
  const auto subject = Shifted(background, Eigen::Vector2d(12.0, 6.0));
  LayerBlendOptions plain = NoSlowShift();
  plain.shape_weight = 0.0;  // the data terms alone: exactly the blend
  LayerBlend a(g.u, g.v, NoSlowShift()), b(g.u, g.v, plain);
  std::vector<Eigen::Vector2f> out_a, out_b;
  LayerBlendReport ra, rb;
  a.Blend(subject, background, Region(), 0.0, 840, 460, &out_a, &ra);
  b.Blend(subject, background, Region(), 0.0, 840, 460, &out_b, &rb);
  EXPECT_GT(ra.min_cell_ratio, rb.min_cell_ratio + 0.02)
      << "optimized " << ra.min_cell_ratio << ", plain " << rb.min_cell_ratio;
}

TEST(LayerBlendTest, TheCapBoundsTheOffsetAndTheStretch) {
  const Grid g;
  const auto background = g.Background();
  const auto subject = Shifted(background, Eigen::Vector2d(60.0, 0.0));
  LayerBlendOptions capped = YieldingToTheBackground(NoSlowShift()),
                    uncapped = YieldingToTheBackground(NoSlowShift());
  capped.max_offset = 0.4;
  uncapped.max_offset = 0.0;
  capped.min_cell_ratio = uncapped.min_cell_ratio = 0.0;  // the cap alone
  LayerBlend a(g.u, g.v, capped), b(g.u, g.v, uncapped);
  std::vector<Eigen::Vector2f> out_a, out_b;
  LayerBlendReport ra, rb;
  a.Blend(subject, background, Region(), 0.0, 840, 460, &out_a, &ra);
  b.Blend(subject, background, Region(), 0.0, 840, 460, &out_b, &rb);
  EXPECT_NEAR(ra.capped_offset_px, 0.4 * 50, 1e-6);
  EXPECT_NEAR(rb.capped_offset_px, 60.0, 0.05);
  // At the head centre the capped mesh moves by the cap only.
  const int centre = 9 * 33 + 16;  // vertex (319.5, 179.5): inside the core
  EXPECT_NEAR((out_a[centre] - background[centre]).x(), 20.0, 1e-3);
  EXPECT_GT(ra.min_cell_ratio, rb.min_cell_ratio + 0.1);
  EXPECT_EQ(ra.folded_cells, 0);
  // Yielding to the subject, the rest of the offset (60 - 20 px) shifts the
  // whole frame instead: the core follows the subject layer exactly, the
  // far background moves by 40 px, and the band bends exactly as much as
  // the capped band above (the same mesh plus a translation).
  LayerBlendOptions yielding = capped;
  yielding.yield_to_subject = true;
  LayerBlend c(g.u, g.v, yielding);
  std::vector<Eigen::Vector2f> out_c;
  LayerBlendReport rc;
  c.Blend(subject, background, Region(), 0.0, 840, 460, &out_c, &rc);
  EXPECT_NEAR(rc.capped_offset_px, 0.4 * 50, 1e-6);
  EXPECT_NEAR((out_c[centre] - background[centre]).x(), 60.0, 1e-3);
  EXPECT_NEAR((out_c[0] - background[0]).x(), 40.0, 1e-3);  // a corner
  for (int k = 0; k < g.n(); ++k) {
    const Eigen::Vector2f moved = out_a[k] + Eigen::Vector2f(40.0f, 0.0f);
    EXPECT_LT((out_c[k] - moved).norm(), 1e-3f) << "vertex " << k;
  }
  EXPECT_NEAR(rc.min_cell_ratio, ra.min_cell_ratio, 1e-4);  // float mesh
  EXPECT_DOUBLE_EQ(rc.protrusion_keep, 1.0);
}

// No undefined pixels: when the subject layer would pull vertices out of
// the input frame, the offset is scaled towards the background layer until
// every vertex is inside.
TEST(LayerBlendTest, PullsTowardsTheBackgroundInsteadOfLeavingTheFrame) {
  const Grid g;
  // The background layer exactly fills a 640 x 360 input.
  std::vector<Eigen::Vector2f> background(g.n());
  for (int k = 0; k < g.n(); ++k) background[k] = g.At(k).cast<float>();
  const auto subject = Shifted(
      background, Eigen::Vector2d(0.0, 15.0));  // shoulders off the bottom
  LayerBlend blend(g.u, g.v, YieldingToTheBackground(NoSlowShift()));
  std::vector<Eigen::Vector2f> out;
  LayerBlendReport rep;
  blend.Blend(subject, background, Region(), 0.0, 640, 360, &out, &rep);
  EXPECT_LT(rep.protrusion_keep, 0.05);
  for (const auto& p : out) {
    EXPECT_GE(p.x(), 0.0f);
    EXPECT_GE(p.y(), 0.0f);
    EXPECT_LE(p.x(), 639.0f);
    EXPECT_LE(p.y(), 359.0f);
  }
}

// No squeezed cell: a layer offset that turns across the band (the subject
// layer rotated about the head centre, as a violent roll leaves it) has no
// offset at the head centre for the cap to act on, yet it squeezes the
// band's cells. The offset is then scaled towards the background layer,
// as far as the floor requires and no further.
TEST(LayerBlendTest, PullsTowardsTheBackgroundInsteadOfSqueezingACell) {
  const Grid g;
  const auto background = g.Background();
  const Eigen::Vector2d c = Region().head_centre + Eigen::Vector2d(100, 50);
  const double a = 35.0 * M_PI / 180.0;
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(a).toRotationMatrix();
  std::vector<Eigen::Vector2f> subject(g.n());
  for (int k = 0; k < g.n(); ++k)
    subject[k] = (c + R * (background[k].cast<double>() - c)).cast<float>();
  LayerBlendOptions off = YieldingToTheBackground(NoSlowShift());
  off.min_cell_ratio = 0.0;
  LayerBlend free_blend(g.u, g.v, off),
      guarded(g.u, g.v, YieldingToTheBackground(NoSlowShift()));
  std::vector<Eigen::Vector2f> out_free, out;
  LayerBlendReport rf, rep;
  // A large input: no vertex leaves it, so only the squeeze can pull.
  free_blend.Blend(subject, background, Region(), 0.0, 4000, 4000, &out_free,
                   &rf);
  guarded.Blend(subject, background, Region(), 0.0, 4000, 4000, &out, &rep);
  ASSERT_LT(rf.min_cell_ratio, 0.45)
      << "the case must squeeze without the floor";
  EXPECT_NEAR(rf.offset_px, 0.0, 0.5);  // nothing at the head centre to cap
  EXPECT_DOUBLE_EQ(rep.protrusion_keep, 1.0);
  EXPECT_GT(rep.distortion_keep, 0.05);
  EXPECT_LT(rep.distortion_keep, 1.0);
  EXPECT_GE(rep.min_cell_ratio, 0.5 - 1e-3);
  EXPECT_LT(rep.min_cell_ratio, 0.52);  // pulled only as far as needed
  EXPECT_EQ(rep.folded_cells, 0);
  // The same solve, scaled: every vertex at keep of its free offset.
  for (int k = 0; k < g.n(); ++k) {
    const Eigen::Vector2f want =
        background[k] +
        static_cast<float>(rep.distortion_keep) * (out_free[k] - background[k]);
    EXPECT_LT((out[k] - want).norm(), 1e-3f) << "vertex " << k;
  }
}

// Yielding to the subject, the same squeeze is pulled towards the subject
// layer instead (a rotated grid: every cell's ratio 1): every vertex at the
// kept fraction of its departure from the subject layer, the floor met
// and no further, and the head centre exactly where the subject layer has
// it, whatever the pull.
TEST(LayerBlendTest, YieldingToTheSubjectPullsTowardsTheSubjectLayer) {
  const Grid g;
  const auto background = g.Background();
  const Eigen::Vector2d c = Region().head_centre + Eigen::Vector2d(100, 50);
  const Eigen::Matrix2d R =
      Eigen::Rotation2Dd(35.0 * M_PI / 180.0).toRotationMatrix();
  std::vector<Eigen::Vector2f> subject(g.n());
  for (int k = 0; k < g.n(); ++k)
    subject[k] = (c + R * (background[k].cast<double>() - c)).cast<float>();
  LayerBlendOptions off = NoSlowShift();
  off.min_cell_ratio = 0.0;
  ASSERT_TRUE(off.yield_to_subject) << "the default";
  LayerBlend free_blend(g.u, g.v, off), guarded(g.u, g.v, NoSlowShift());
  std::vector<Eigen::Vector2f> out_free, out;
  LayerBlendReport rf, rep;
  free_blend.Blend(subject, background, Region(), 0.0, 4000, 4000, &out_free,
                   &rf);
  guarded.Blend(subject, background, Region(), 0.0, 4000, 4000, &out, &rep);
  ASSERT_LT(rf.min_cell_ratio, 0.45);
  EXPECT_GT(rep.distortion_keep, 0.05);
  EXPECT_LT(rep.distortion_keep, 1.0);
  EXPECT_GE(rep.min_cell_ratio, 0.5 - 1e-3);
  EXPECT_LT(rep.min_cell_ratio, 0.52);
  EXPECT_EQ(rep.folded_cells, 0);
  int core = 0;
  for (int k = 0; k < g.n(); ++k) {
    const Eigen::Vector2f want =
        subject[k] +
        static_cast<float>(rep.distortion_keep) * (out_free[k] - subject[k]);
    EXPECT_LT((out[k] - want).norm(), 1e-3f) << "vertex " << k;
    if (guarded.vertex_blend()[k] >= 1.0) {
      EXPECT_LT((out[k] - subject[k]).norm(), 1e-3f) << "core vertex " << k;
      ++core;
    }
  }
  EXPECT_GT(core, 20);
}

// A whole-frame shift that lags behind the layers (the slow part of an
// offset held for seconds) while the background layer has reached the
// input's top edge: the frame shifted by it would leave the input.
// Yielding to the background, the pull drags the head towards the
// background layer; yielding to the subject, the cap's rest moves the
// frame with the subject and the head stays exactly on the subject layer,
// every vertex inside.
TEST(LayerBlendTest, ALaggingShiftNeverDragsTheHeadWhenYieldingToTheSubject) {
  const Grid g;
  std::vector<Eigen::Vector2f> low(g.n()), top(g.n());
  for (int k = 0; k < g.n(); ++k) {
    low[k] = (g.At(k) + Eigen::Vector2d(100, 100)).cast<float>();  // bottom
    top[k] = (g.At(k) + Eigen::Vector2d(100, 0)).cast<float>();    // top edge
  }
  const int centre = 9 * 33 + 16;  // in the core
  for (const bool to_subject : {false, true}) {
    LayerBlendOptions o = Straddling();
    o.yield_to_subject = to_subject;
    LayerBlend blend(g.u, g.v, o);
    std::vector<Eigen::Vector2f> out;
    LayerBlendReport rep;
    // The subject 60 px above the background for 20 s: the shift learns it.
    for (int i = 0; i < 600; ++i) {
      blend.Blend(Shifted(low, {0, -60}), low, Region(), i ? 1.0 / 30 : 0.0,
                  840, 460, &out, &rep);
    }
    ASSERT_NEAR(rep.shift_px, 60.0, 0.5);
    // Then the background at the top edge, the subject 20 px below it.
    const auto subject = Shifted(top, {0, 20});
    blend.Blend(subject, top, Region(), 1.0 / 30, 840, 460, &out, &rep);
    for (const auto& p : out) {
      EXPECT_GE(p.y(), -1e-3f);
      EXPECT_LE(p.y(), 459.0f + 1e-3f);
    }
    const double head_error = (out[centre] - subject[centre]).norm();
    if (to_subject) {
      EXPECT_LT(head_error, 1e-3);
    } else {
      EXPECT_LT(rep.protrusion_keep, 1.0);
      EXPECT_GT(head_error, 10.0);  // over half way to the background layer
    }
  }
}

TEST(LayerBlendTest, BlendZeroIsExactlyTheBackgroundLayer) {
  const Grid g;
  const auto background = g.Background();
  LayerBlend blend(g.u, g.v, LayerBlendOptions());
  std::vector<Eigen::Vector2f> out;
  LayerBlendReport rep;
  blend.Blend(Shifted(background, {9, 9}), background, Region(0.0), 1.0 / 30,
              840, 460, &out, &rep);
  EXPECT_FALSE(rep.layered);
  for (int k = 0; k < g.n(); ++k) EXPECT_EQ(out[k], background[k]);
}

// The offset's slow part shifts the whole frame: a constant offset held for
// seconds ends up in the shift, and the band has nothing left to absorb.
TEST(LayerBlendTest, AHeldOffsetMovesIntoTheWholeFrameShift) {
  const Grid g;
  const auto background = g.Background();
  const Eigen::Vector2d T(10.0, 0.0);
  LayerBlend blend(g.u, g.v, Straddling());
  std::vector<Eigen::Vector2f> out;
  LayerBlendReport rep;
  // Start with no offset, then step to T and hold it 20 s.
  blend.Blend(background, background, Region(), 0.0, 840, 460, &out, &rep);
  double first_fast = -1.0;
  for (int i = 0; i < 600; ++i) {
    blend.Blend(Shifted(background, T), background, Region(), 1.0 / 30, 840,
                460, &out, &rep);
    if (i == 0) first_fast = rep.offset_px;
  }
  EXPECT_NEAR(first_fast, 10.0, 0.5);  // a step is fast: the band takes it
  EXPECT_LT(rep.offset_px, 0.3);
  EXPECT_NEAR(rep.shift_px, 10.0, 0.3);
  const Eigen::Vector2d far =
      (out[0] - background[0]).cast<double>();  // a corner
  EXPECT_NEAR(far.x(), 10.0, 0.3);
}

TEST(LayerBlendTest, RejectsBadOptions) {
  LayerBlendOptions o;
  EXPECT_TRUE(ValidateLayerBlendOptions(o).ok());
  o.band_width = 0.0;
  EXPECT_FALSE(ValidateLayerBlendOptions(o).ok());
  o = LayerBlendOptions();
  o.band_inside = 1.5;
  EXPECT_FALSE(ValidateLayerBlendOptions(o).ok());
  o = LayerBlendOptions();
  o.max_offset = NAN;
  const Status s = ValidateLayerBlendOptions(o);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("max_offset"), std::string::npos) << s.message();
  o = LayerBlendOptions();
  o.min_cell_ratio = 1.0;  // no mesh but the background's could pass
  const Status m = ValidateLayerBlendOptions(o);
  EXPECT_FALSE(m.ok());
  EXPECT_NE(m.message().find("min_cell_ratio"), std::string::npos)
      << m.message();
  o = LayerBlendOptions();
  o.face_core_cells = -1.0;
  const Status c = ValidateLayerBlendOptions(o);
  EXPECT_FALSE(c.ok());
  EXPECT_NE(c.message().find("face_core"), std::string::npos) << c.message();
  SubjectRegionOptions r;
  r.ramp_s = 0.0;
  EXPECT_FALSE(ValidateSubjectRegionOptions(r).ok());
}
}  // namespace
}  // namespace steadiface
