// The composite's pieces on synthetic pictures with known geometry: the
// homography between two virtual cameras, the background plate, the subject
// matte and the compositor.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/composite/background_plate.h"
#include "steadiface_core/composite/compositor.h"
#include "steadiface_core/composite/guided_filter.h"
#include "steadiface_core/composite/layer_homography.h"
#include "steadiface_core/pipeline/debug_overlay.h"
#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/warp/warper.h"
#include "test_util.h"

namespace steadiface {
namespace {

OutputGeometry Geometry() {
  OutputGeometry g;
  EXPECT_TRUE(OutputGeometry::Create(testing_util::Model640x360(), OutputOptions(), &g).ok());
  return g;
}

Eigen::Quaterniond Rot(double rx, double ry, double rz) {
  return ExpSO3(Eigen::Vector3d(rx, ry, rz));
}

// A world-anchored scene: a textured panorama seen by the reference view
// (identity rotation, the panorama's pixel K), rendered into any view.
struct Scene {
  LayerView reference;
  cv::Mat texture;
  Scene(const OutputGeometry& g) {
    reference = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
    reference.K(0, 2) += 200;
    reference.K(1, 2) += 150;
    texture = cv::Mat(g.height() + 300, g.width() + 400, CV_8UC3);
    cv::RNG rng(7);
    rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(texture, texture, cv::Size(0, 0), 2.0);
    texture.convertTo(texture, -1, 3.0, -250.0);  // contrast back up
  }
  cv::Mat Render(const LayerView& v, const cv::Size& size) const {
    cv::Mat out;
    const cv::Rect src(0, 0, texture.cols, texture.rows), dst(0, 0, size.width, size.height);
    cv::warpPerspective(texture, out, RectMap(HomographyBetween(reference, v), src, 1.0, dst, 1.0),
                        size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REFLECT);
    return out;
  }
};

double MeanAbs(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const cv::Scalar m = cv::mean(d, mask);
  return (m[0] + m[1] + m[2]) / 3.0;
}

TEST(LayerHomographyTest, MapsAWorldDirectionBetweenTwoVirtualCameras) {
  const OutputGeometry g = Geometry();
  const LayerView a = OutputView(g, Rot(0.02, -0.03, 0.01), Eigen::Vector2d(0.01, -0.02));
  const LayerView b = OutputView(g, Rot(-0.01, 0.02, 0.03), Eigen::Vector2d(-0.015, 0.005));
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(0.1, -0.05, 1.0), Eigen::Vector3d(-0.2, 0.1, 1.0)}) {
    const Eigen::Vector2d pa = (a.K * (a.R * d)).hnormalized();
    const Eigen::Vector2d pb = (b.K * (b.R * d)).hnormalized();
    EXPECT_LT(((HomographyBetween(b, a) * pa.homogeneous()).hnormalized() - pb).norm(), 1e-9);
  }
  // The output's pixels follow OutputGeometry's own mapping (t moves the
  // principal point by t / scale).
  const LayerView c = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d(0.01, 0.0));
  const LayerView z = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
  const Eigen::Vector2d shift = (HomographyBetween(c, z) * Eigen::Vector3d(100, 50, 1)).hnormalized();
  const Eigen::Vector2d expected =
      g.VirtualToOutputPixel(g.OutputPixelToVirtual(Eigen::Vector2d(100, 50)) + Eigen::Vector2d(0.01, 0));
  EXPECT_LT((shift - expected).norm(), 1e-9);
}

TEST(LayerHomographyTest, RectMapSamplesTheRightPixelAtAnyScale) {
  // A dot at view pixel (120, 80) of a 1/4-scale picture lands at (120, 80)
  // of a full-scale rectangle starting at (100, 60) through the identity.
  cv::Mat small = cv::Mat::zeros(90, 160, CV_32F);
  small.at<float>(80 / 4, 120 / 4) = 1.0f;  // view pixels 120..123 x 80..83
  cv::Mat out;
  const cv::Rect dst(100, 60, 40, 40);
  cv::warpPerspective(small, out, RectMap(Eigen::Matrix3d::Identity(), cv::Rect(0, 0, 640, 360), 0.25,
                                          dst, 1.0),
                      dst.size(), cv::INTER_NEAREST | cv::WARP_INVERSE_MAP);
  EXPECT_EQ(out.at<float>(80 - 60, 120 - 100), 1.0f);
  EXPECT_EQ(out.at<float>(83 - 60, 123 - 100), 1.0f);
  EXPECT_EQ(out.at<float>(84 - 60, 124 - 100), 0.0f);
  EXPECT_EQ(cv::countNonZero(out), 16);
}

TEST(BackgroundPlateTest, HoldsTheSceneWhatASubjectUncoversAndForgetsOldPixels) {
  const OutputGeometry g = Geometry();
  const Scene scene(g);
  BackgroundPlateOptions o;
  o.max_age_s = 1.0;
  BackgroundPlate plate(g, o);
  const cv::Size size(g.width(), g.height());
  const cv::Rect roi(200, 80, 240, 200);
  // The background camera sways by up to 1.5 degrees; a subject (a square
  // of matte 1) moves across the roi and back, never over its right quarter
  // after frame 0.
  double mae = 0.0;
  int measured = 0;
  for (int i = 0; i < 60; ++i) {
    const double t = i / 30.0;
    const LayerView v = OutputView(g, Rot(0.02 * std::sin(2 * t), 0.025 * std::sin(3 * t), 0.0),
                                   Eigen::Vector2d::Zero());
    plate.Begin(v, t);
    const cv::Mat picture = scene.Render(v, size);
    cv::Mat matte = cv::Mat::zeros(roi.size(), CV_32F);
    const int x0 = 20 + static_cast<int>(100 * (1 - std::cos(2 * M_PI * t / 2)) / 2);
    matte(cv::Rect(x0, 40, 80, 120)).setTo(1.0f);
    if (i >= 40) {  // the plate where the subject is now was seen before
      cv::Mat colour, valid;
      plate.Sample(roi, &colour, &valid);
      const cv::Mat covered = (matte > 0.5) & (valid > 0.99);
      ASSERT_GT(cv::countNonZero(covered), 2000) << "frame " << i;
      mae += MeanAbs(colour, picture(roi), covered);
      ++measured;
    }
    EXPECT_TRUE(plate.Update(picture(roi), matte, roi, 0.1f));
  }
  EXPECT_LT(mae / measured, 4.0);  // bilinear resampling of a sharp texture
  // Unseen for longer than max_age: expired.
  plate.Begin(OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero()), 10.0);
  cv::Mat colour, valid;
  plate.Sample(roi, &colour, &valid);
  EXPECT_EQ(cv::countNonZero(valid > 0.0), 0);
  EXPECT_EQ(plate.restarts(), 0);
}

TEST(BackgroundPlateTest, RestartsOnAsceneCutAndOnALargeTurnAndReprojectsOnADrift) {
  const OutputGeometry g = Geometry();
  const Scene scene(g);
  BackgroundPlate plate(g, BackgroundPlateOptions());
  const cv::Size size(g.width(), g.height());
  const cv::Rect roi(100, 60, 300, 200);
  const cv::Mat none = cv::Mat::zeros(roi.size(), CV_32F);
  LayerView v = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
  plate.Begin(v, 0.0);
  EXPECT_TRUE(plate.Update(scene.Render(v, size)(roi), none, roi, 0.1f));
  // The same view, another scene: a cut.
  plate.Begin(v, 0.033);
  cv::Mat other = 255 - scene.Render(v, size);
  EXPECT_FALSE(plate.Update(other(roi), none, roi, 0.1f));
  EXPECT_EQ(plate.restarts(), 1);
  // A slow pan of 10 degrees (130 px, more than the 96 px margin):
  // reprojected, the scene still where it was.
  for (int i = 0; i <= 25; ++i) {
    v = OutputView(g, Rot(0.0, 0.007 * i, 0.0), Eigen::Vector2d::Zero());
    plate.Begin(v, 0.1 + i / 30.0);
    EXPECT_TRUE(plate.Update(scene.Render(v, size)(roi), none, roi, 0.1f));
  }
  EXPECT_GE(plate.reprojections(), 1);
  EXPECT_EQ(plate.restarts(), 1);
  cv::Mat colour, valid;
  plate.Sample(roi, &colour, &valid);
  EXPECT_LT(MeanAbs(colour, scene.Render(v, size)(roi), valid > 0.99), 5.0);
  // A turn of 30 degrees: restarted.
  plate.Begin(OutputView(g, Rot(0.0, 0.52, 0.0), Eigen::Vector2d::Zero()), 2.0);
  EXPECT_EQ(plate.restarts(), 2);
}

// The plate learns each pixel from where its view point falls in the
// picture. Through a view turned by 5.1 degrees from the plate's anchor the
// homography between them bends: the plate must still hold the scene where
// it is, as sharp as through the anchor's own view.
TEST(BackgroundPlateTest, LearnsThroughAViewTurnedFromItsAnchorWithoutSmearing) {
  const OutputGeometry g = Geometry();
  const Scene scene(g);
  const cv::Size size(g.width(), g.height());
  const cv::Rect roi(40, 30, 560, 300);
  const cv::Mat none = cv::Mat::zeros(roi.size(), CV_32F);
  const auto error = [&](const LayerView& v) {
    BackgroundPlate plate(g, BackgroundPlateOptions());
    const LayerView anchor = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
    plate.Begin(anchor, 0.0);  // anchors the plate; learns nothing
    plate.Begin(v, 0.033);
    EXPECT_EQ(plate.reprojections(), 0);
    EXPECT_TRUE(plate.Update(scene.Render(v, size)(roi), none, roi, 0.1f));
    cv::Mat colour, valid;
    plate.Sample(roi, &colour, &valid);
    EXPECT_GT(cv::countNonZero(valid > 0.99), roi.area() * 8 / 10);
    return MeanAbs(colour, scene.Render(v, size)(roi), valid > 0.99);
  };
  const double straight = error(OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero()));
  const double turned = error(OutputView(g, Rot(0.04, 0.08, 0.0), Eigen::Vector2d::Zero()));
  // Through the anchor's own view every view point is a whole pixel: the
  // plate is the picture. Turned, the sharp texture loses to the two
  // bilinear resamplings (learnt, sampled back): 1.58 grey levels with the
  // view points exact (a 4 px mesh); a fixed 64 px mesh gives 1.79, and a
  // fixed 128 px one 3.42.
  EXPECT_LT(straight, 0.01);
  EXPECT_LT(turned, 1.65);
}

// A fringe of the subject that the matte let through on one frame (a strip
// of hair colour where the matte says scene), then the scene there. With
// confirm_frames 1 the plate keeps the fringe while it is fresh (the scene
// is its outlier); with the default the scene replaces it on the next frame.
// A pixel that the scene has confirmed turns a fringe away.
TEST(BackgroundPlateTest, TheSceneReplacesAFringeTakenFirstAndTurnsOneAwayOnceConfirmed) {
  const OutputGeometry g = Geometry();
  const Scene scene(g);
  const cv::Size size(g.width(), g.height());
  const cv::Rect roi(100, 60, 300, 200), strip(100, 50, 40, 100);  // strip: in the roi
  const cv::Mat none = cv::Mat::zeros(roi.size(), CV_32F);
  const LayerView v = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
  const cv::Mat clean = scene.Render(v, size);
  cv::Mat fringe = clean.clone();
  fringe(roi)(strip).setTo(cv::Scalar(40, 60, 120));
  cv::Mat strip_mask = cv::Mat::zeros(roi.size(), CV_8U);
  strip_mask(strip).setTo(255);
  const auto strip_error = [&](const BackgroundPlate& plate) {
    cv::Mat colour, valid;
    plate.Sample(roi, &colour, &valid);
    EXPECT_EQ(cv::countNonZero((valid > 0.99) & strip_mask), strip.area());
    return MeanAbs(colour, clean(roi), strip_mask);
  };
  ASSERT_EQ(BackgroundPlateOptions().confirm_frames, 4);
  for (const int confirm : {1, 4}) {
    SCOPED_TRACE(confirm);
    BackgroundPlateOptions o;
    o.confirm_frames = confirm;
    BackgroundPlate plate(g, o);
    for (int i = 0; i < 5; ++i) {
      plate.Begin(v, i / 30.0);
      ASSERT_TRUE(plate.Update((i == 0 ? fringe : clean)(roi), none, roi, 0.1f));
      const double error = strip_error(plate);
      if (i == 0 || confirm == 1) {
        EXPECT_GT(error, 40.0) << "frame " << i;  // the fringe
      } else {
        EXPECT_LT(error, 3.0) << "frame " << i;  // the scene
      }
    }
    // Four frames of the scene confirmed it (with 4): a fringe now is turned
    // away. (With 1 the fringe taken first is still there.)
    plate.Begin(v, 5 / 30.0);
    ASSERT_TRUE(plate.Update(fringe(roi), none, roi, 0.1f));
    if (confirm == 4) EXPECT_LT(strip_error(plate), 3.0);
  }
}

// The subject region of a disc of radius r around c (head only).
SubjectRegion Disc(const Eigen::Vector2d& c, double r) {
  SubjectRegion region;
  region.valid = true;
  region.head_centre = c;
  region.face_centre = c;
  region.head_axes = Eigen::Vector2d(r, r);
  region.jaw_width = 1.4 * r;
  region.face_height = 1.2 * r;
  region.torso = false;
  region.blend = 1.0;
  return region;
}

// What a swing run scored over its last 30 frames (means).
struct SwingScore {
  double iou = 0.0;         // the matte against the disc, its edge aside
  double mae = 0.0;         // the output against the truth [grey levels]
  double plate_share = 0.0; // of the uncovered pixels, the plate's share
  double min_plate_share = 1.0;
};

// The scene stands still in the background layer. The subject, a textured
// disc of radius r [px] around (320, 190), stands still in the subject
// layer, whose view swings by `swing` rad (0.09: ~+-50 px) at 1.2 Hz against
// the background's: what it uncovers must come from the plate, and the disc
// must be where the subject layer puts it.
SwingScore RunSwing(double r, double swing) {
  const OutputGeometry g = Geometry();
  const Scene scene(g);
  const cv::Size size(g.width(), g.height());
  std::unique_ptr<Compositor> c;
  EXPECT_TRUE(Compositor::Create(g, CompositeOptions(), &c).ok());
  cv::Mat face(size, CV_8UC3);
  cv::RNG rng(3);
  rng.fill(face, cv::RNG::UNIFORM, cv::Scalar(150, 100, 60), cv::Scalar(230, 170, 120));
  const Eigen::Vector2d centre(320, 190);
  const int ri = static_cast<int>(r);
  cv::Mat disc = cv::Mat::zeros(size, CV_8U);
  cv::circle(disc, cv::Point(320, 190), ri, cv::Scalar(255), -1, cv::LINE_AA);
  const LayerView background = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
  SwingScore score;
  int n = 0;
  for (int i = 0; i < 75; ++i) {
    const double t = i / 30.0;
    const LayerView subject = OutputView(g, Rot(0.0, swing * std::sin(2 * M_PI * 1.2 * t), 0.0),
                                         Eigen::Vector2d::Zero());
    // The subject layer's picture: the scene as that view sees it, the disc
    // fixed in it. The background layer's: the scene, the disc where the
    // subject view's disc lands in the background view.
    cv::Mat S = scene.Render(subject, size);
    face.copyTo(S, disc);
    const Eigen::Matrix3d H_bs = HomographyBetween(background, subject);
    cv::Mat disc_b, face_b;
    const cv::Rect whole(0, 0, size.width, size.height);
    cv::warpPerspective(disc, disc_b, RectMap(H_bs.inverse(), whole, 1.0, whole, 1.0), size,
                        cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    cv::warpPerspective(face, face_b, RectMap(H_bs.inverse(), whole, 1.0, whole, 1.0), size,
                        cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    cv::Mat B = scene.Render(background, size);
    face_b.copyTo(B, disc_b > 127);
    const Eigen::Vector2d c_b = (H_bs * centre.homogeneous()).hnormalized();
    cv::Mat out;
    EXPECT_TRUE(c->Compose(S, subject, B, background, Disc(c_b, r), t, &out).ok());
    if (i < 45) continue;  // a cycle and a half to learn the scene
    // The matte against the disc in the background view (3 px from its edge
    // not scored).
    cv::Mat truth = cv::Mat::zeros(size, CV_8U), est = cv::Mat::zeros(size, CV_8U);
    cv::circle(truth, cv::Point2d(c_b.x(), c_b.y()), ri - 3, cv::Scalar(255), -1);
    cv::Mat band = cv::Mat::zeros(size, CV_8U);
    cv::circle(band, cv::Point2d(c_b.x(), c_b.y()), ri, cv::Scalar(255), 7);
    const CompositeReport& rep = c->report();
    est(rep.background_roi).setTo(255, c->background_matte() >= 0.5);
    const cv::Mat scored = band == 0;
    cv::Mat t_in = truth & scored, e_in = est & scored;
    score.iou += static_cast<double>(cv::countNonZero(t_in & e_in)) / cv::countNonZero(t_in | e_in);
    // The output against the truth: the disc where the subject layer holds
    // it (the centre), the scene as the background layer sees it elsewhere.
    cv::Mat expected = scene.Render(background, size);
    face.copyTo(expected, disc);
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(15, 15));
    cv::Mat away, edge_b, near_disc;
    cv::dilate(disc, away, k);
    cv::dilate(disc_b, edge_b, k);
    cv::erode(disc, near_disc, k);  // scored: the disc's interior and the uncovered scene
    const cv::Mat uncovered = (edge_b > 0) & (away == 0);
    score.mae += MeanAbs(out, expected, (near_disc > 0) | uncovered);
    score.plate_share += rep.plate_share;
    score.min_plate_share = std::min(score.min_plate_share, rep.plate_share);
    ++n;
  }
  score.iou /= n;
  score.mae /= n;
  score.plate_share /= n;
  return score;
}

TEST(CompositorTest, PutsTheSubjectWhereItsLayerHoldsItAndTheSceneWhereItsLayerHoldsIt) {
  const SwingScore s = RunSwing(60.0, 0.09);
  EXPECT_GT(s.min_plate_share, 0.8);
  EXPECT_GT(s.iou, 0.9);
  EXPECT_LT(s.mae, 8.0);
}

TEST(CompositorTest, ThePlateLearnsWhereASmallSubjectSwungBeyondItsSearchRegion) {
  // A 20 px disc swung by +-50 px: its matte's search region (0.5 jaw widths
  // around it) never holds where it will be at the other end of the swing
  // while that is the scene. The plate learns where the region was over its
  // lifetime, so what the disc uncovers there is the scene it saw.
  const SwingScore s = RunSwing(20.0, 0.09);
  std::printf("small disc: plate share %.3f (min %.3f), iou %.3f, output error %.2f\n",
              s.plate_share, s.min_plate_share, s.iou, s.mae);
  EXPECT_GT(s.plate_share, 0.8);
  EXPECT_LT(s.mae, 8.0);
}

TEST(CompositorTest, TheDebugOverlayDrawsTheMattesOutlineWhereTheSubjectIs) {
  // A disc subject on a scene, both still: the matte's outline is drawn
  // around the disc (through an identity mesh), nowhere far from it.
  const OutputGeometry g = Geometry();
  const Scene scene(g);
  const cv::Size size(g.width(), g.height());
  std::unique_ptr<Compositor> c;
  ASSERT_TRUE(Compositor::Create(g, CompositeOptions(), &c).ok());
  const LayerView v = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
  cv::Mat picture = scene.Render(v, size), out;
  cv::circle(picture, cv::Point(320, 180), 60, cv::Scalar(40, 90, 200), -1, cv::LINE_AA);
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(c->Compose(picture, v, picture, v, Disc(Eigen::Vector2d(320, 180), 60), i / 30.0,
                           &out).ok());
  }
  WarpMesh identity;
  identity.cols = identity.rows = 2;
  identity.u = {0.0, size.width - 1.0};
  identity.v = {0.0, size.height - 1.0};
  identity.source = {Eigen::Vector2f(0, 0), Eigen::Vector2f(size.width - 1, 0),
                     Eigen::Vector2f(0, size.height - 1),
                     Eigen::Vector2f(size.width - 1, size.height - 1)};
  cv::Mat dbg = cv::Mat::zeros(size, CV_8UC3);
  DrawCompositeOverlay(identity, *c, &dbg);
  std::vector<cv::Mat> ch;
  cv::split(dbg, ch);
  const cv::Mat magenta = (ch[0] > 200) & (ch[2] > 200) & (ch[1] < 60);
  ASSERT_GT(cv::countNonZero(magenta), 200);
  // Every magenta pixel lies within 12 px of the disc's edge.
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      if (!magenta.at<uchar>(y, x)) continue;
      EXPECT_NEAR(std::hypot(x - 320.0, y - 180.0), 60.0, 12.0) << x << "," << y;
    }
  }
}

TEST(CompositorTest, WithoutASubjectTheOutputIsTheBackgroundLayer) {
  const OutputGeometry g = Geometry();
  std::unique_ptr<Compositor> c;
  ASSERT_TRUE(Compositor::Create(g, CompositeOptions(), &c).ok());
  cv::Mat S(g.height(), g.width(), CV_8UC3, cv::Scalar(10, 20, 30));
  cv::Mat B(g.height(), g.width(), CV_8UC3, cv::Scalar(200, 100, 50)), out;
  const LayerView v = OutputView(g, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero());
  ASSERT_TRUE(c->Compose(S, v, B, v, SubjectRegion(), 0.0, &out).ok());
  EXPECT_FALSE(c->report().active);
  EXPECT_EQ(cv::norm(out, B, cv::NORM_INF), 0.0);
  // Mismatched pictures are refused with a message.
  cv::Mat small(10, 10, CV_8UC3);
  EXPECT_FALSE(c->Compose(small, v, B, v, SubjectRegion(), 0.0, &out).ok());
}

TEST(CompositeOptionsTest, ValidationNamesTheBadField) {
  CompositeOptions o;
  EXPECT_TRUE(ValidateCompositeOptions(o).ok());
  o.matte.scale = 0;
  Status s = ValidateCompositeOptions(o);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("scale"), std::string::npos);
  o = CompositeOptions();
  o.plate.max_age_s = -1;
  s = ValidateCompositeOptions(o);
  EXPECT_NE(s.message().find("max_age_s"), std::string::npos);
  o = CompositeOptions();
  o.plate_distance_px = 100;
  EXPECT_FALSE(ValidateCompositeOptions(o).ok());
}

TEST(GuidedFilterTest, KeepsAnEdgeTheGuideShowsAndSmoothsWhereItShowsNone) {
  // A step in the guide at x = 50; the input a noisy, blurred step at x = 46.
  cv::Mat guide(40, 100, CV_32F, cv::Scalar(0.2f)), p(40, 100, CV_32F, cv::Scalar(0.0f));
  guide(cv::Rect(50, 0, 50, 40)).setTo(0.8f);
  p(cv::Rect(46, 0, 54, 40)).setTo(1.0f);
  cv::Mat q;
  GuidedFilter(guide, p, 8, 1e-3, &q);
  EXPECT_LT(q.at<float>(20, 30), 0.1f);
  EXPECT_GT(q.at<float>(20, 70), 0.9f);
  // The transition sits on the guide's edge: between 49 and 50 it jumps.
  EXPECT_GT(q.at<float>(20, 50) - q.at<float>(20, 49), 0.3f);
  // The fast form (coefficients at half resolution, applied to the full
  // guide) stays within 0.1 of the exact one away from the edge.
  cv::Mat g2, p2, a, b, A, B;
  cv::resize(guide, g2, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  cv::resize(p, p2, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  GuidedFilterCoefficients(g2, p2, 4, 1e-3, &a, &b);
  cv::resize(a, A, guide.size(), 0, 0, cv::INTER_LINEAR);
  cv::resize(b, B, guide.size(), 0, 0, cv::INTER_LINEAR);
  const cv::Mat fast = A.mul(guide) + B;
  EXPECT_LT(std::abs(fast.at<float>(20, 30) - q.at<float>(20, 30)), 0.1f);
  EXPECT_LT(std::abs(fast.at<float>(20, 70) - q.at<float>(20, 70)), 0.1f);
}

TEST(WarpModeTest, ParsesComposite) {
  WarpMode m;
  ASSERT_TRUE(ParseWarpMode("composite", &m).ok());
  EXPECT_EQ(m, WarpMode::kComposite);
  EXPECT_STREQ(WarpModeName(m), "composite");
  const Status s = ParseWarpMode("mosaic", &m);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("composite"), std::string::npos);
}

}  // namespace
}  // namespace steadiface
