// StabilizerWrapper's warp modes and view: layered and composite through
// the ROS layer, the dynamic crop and the level horizon in the state and
// camera_info.
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "wrapper_test_util.h"

namespace steadiface_ros {
namespace wrapper_test {
namespace {

// warp/mode layered: both virtual cameras in TF, the mode and the blend's
// figures in `state`, a full-size output, the debug image with the region
// drawn, and camera_info for the background layer (most of the frame). A
// reconfigure back to global takes effect from the next frame.
TEST(WrapperTest, LayeredModePublishesBothLayersAndSwitchesBackToGlobal) {
  DebugSink sink;
  steadiface::PipelineOptions po = Options();
  po.landmark_source =
      steadiface::LandmarkSource::kDlib;  // the region needs a face
  po.warp.mode = steadiface::WarpMode::kLayered;
  StabilizerWrapper w(po, WrapperOptions(), &sink);
  const int n = static_cast<int>(TestStream().images.size());
  Feed(&w, TestStream(), 0, n / 2);
  Sink gyro_sink;
  steadiface::PipelineOptions go = Options();
  go.stabilizer.gyro_only = true;
  go.landmark_source = steadiface::LandmarkSource::kNone;
  StabilizerWrapper gyro(go, WrapperOptions(), &gyro_sink);
  Feed(&gyro, TestStream(), 0, n / 2);
  ASSERT_EQ(sink.states.size(), static_cast<size_t>(n / 2));
  size_t background_tf = 0;
  for (const auto& t : sink.tf)
    background_tf += t.child_frame_id == "cam_stabilized_background";
  EXPECT_EQ(background_tf, sink.states.size());
  bool blended = false;
  for (size_t i = 0; i < sink.states.size(); ++i) {
    const auto& st = sink.states[i];
    EXPECT_EQ(st.warp_mode, "layered");
    ASSERT_TRUE(st.has_background_layer);
    EXPECT_EQ(st.folded_cells, 0u);
    EXPECT_GE(st.min_cell_ratio, 0.5);
    EXPECT_GE(st.layer_blend, 0.0);
    EXPECT_LE(st.layer_blend, 1.0);
    blended = blended || st.layer_blend > 0.5;
    // The output's intrinsics are the background layer's: a gyro-only run's.
    ASSERT_LT(i, gyro_sink.infos.size());
    EXPECT_EQ(sink.infos[i]->K[2], gyro_sink.infos[i]->K[2]);
    EXPECT_EQ(sink.infos[i]->K[5], gyro_sink.infos[i]->K[5]);
    EXPECT_EQ(sink.images[i]->width, TestStream().images[0]->width);
  }
  EXPECT_TRUE(blended);  // the face was found and the region applied
  ASSERT_FALSE(sink.debug.empty());
  ExpectAllFinite(sink);
  // Back to global at run time.
  w.RequestLayering(steadiface::WarpMode::kGlobal,
                    steadiface::LayeredWarpOptions());
  Feed(&w, TestStream(), n / 2, n);
  ASSERT_EQ(sink.states.size(), static_cast<size_t>(n));
  EXPECT_EQ(sink.states.back().warp_mode, "global");
  EXPECT_EQ(w.pipeline_options().warp.mode, steadiface::WarpMode::kGlobal);
  EXPECT_EQ(sink.errors.count("reconfigure"), 0u);
}

// warp/mode composite, switched on at run time from global: the mode and
// the composite's figures in `state` (finite, in range), camera_info for
// the background layer, the debug image with the matte; the face's pixels
// where the subject layer holds them.
TEST(WrapperTest, CompositeModeSwitchedOnAtRunTimePublishesItsState) {
  DebugSink sink;
  steadiface::PipelineOptions po = Options();
  po.landmark_source =
      steadiface::LandmarkSource::kDlib;  // the matte needs a face
  StabilizerWrapper w(po, WrapperOptions(), &sink);
  const int n = static_cast<int>(TestStream().images.size());
  Feed(&w, TestStream(), 0, n / 4);
  EXPECT_EQ(sink.states.back().warp_mode, "global");
  w.RequestLayering(steadiface::WarpMode::kComposite, po.warp.layered);
  Feed(&w, TestStream(), n / 4, n);
  ASSERT_EQ(sink.states.size(), static_cast<size_t>(n));
  EXPECT_EQ(w.pipeline_options().warp.mode, steadiface::WarpMode::kComposite);
  Sink gyro_sink;
  steadiface::PipelineOptions go = Options();
  go.stabilizer.gyro_only = true;
  go.landmark_source = steadiface::LandmarkSource::kNone;
  StabilizerWrapper gyro(go, WrapperOptions(), &gyro_sink);
  Feed(&gyro, TestStream());
  bool matted = false;
  for (int i = n / 4; i < n; ++i) {
    const auto& st = sink.states[i];
    EXPECT_EQ(st.warp_mode, "composite");
    ASSERT_TRUE(st.has_background_layer);
    EXPECT_GE(st.matte_mean, 0.0);
    EXPECT_LE(st.matte_mean, 1.0);
    EXPECT_GE(st.plate_share, 0.0);
    EXPECT_LE(st.plate_share + st.fallback_share, 1.0 + 1e-9);
    EXPECT_GE(st.plate_coverage, 0.0);
    EXPECT_LE(st.plate_coverage, 1.0);
    matted = matted || st.matte_mean > 0.05;
    EXPECT_EQ(sink.infos[i]->K[2], gyro_sink.infos[i]->K[2]);
    EXPECT_EQ(sink.images[i]->width, TestStream().images[0]->width);
  }
  EXPECT_TRUE(matted);  // the face was found and cut out
  EXPECT_TRUE(w.CurrentStatus().view_conflict.empty());  // the fixed crop
  ASSERT_FALSE(sink.debug.empty());
  EXPECT_EQ(sink.errors.count("reconfigure"), 0u);
  ExpectAllFinite(sink);
}

// The view (output/crop dynamic, output/horizon level): each frame's state
// carries its crop and camera_info the matching focal length; the horizon
// is levelled from the messages' accelerometer, and without one the state
// says why it is not.
TEST(WrapperTest, TheViewReachesTheStateAndCameraInfo) {
  steadiface::PipelineOptions o = Options();
  o.crop.mode = steadiface::CropMode::kDynamic;
  o.horizon.mode = steadiface::HorizonMode::kLevel;
  Sink sink;
  StabilizerWrapper w(o, WrapperOptions(), &sink);
  Feed(&w, TestStream());
  ASSERT_EQ(sink.states.size(), TestStream().images.size());
  ASSERT_EQ(sink.infos.size(), sink.states.size());
  const double fx0 =
      sink.infos.front()->K[0] * (1.0 - 2.0 * sink.states.front().crop_ratio);
  for (size_t i = 0; i < sink.states.size(); ++i) {
    const steadiface::StabilizerState& s = sink.states[i];
    EXPECT_EQ(s.crop_mode, "dynamic");
    EXPECT_GE(s.crop_ratio, 0.0);
    EXPECT_LE(s.crop_ratio, 0.15);
    // fx in output pixels times the kept width is the same on every frame.
    EXPECT_NEAR(sink.infos[i]->K[0] * (1.0 - 2.0 * s.crop_ratio), fx0,
                1e-6 * fx0)
        << i;
  }
  const WrapperStatus st = w.CurrentStatus();
  EXPECT_EQ(st.horizon_mode, "level");
  EXPECT_TRUE(st.view_conflict.empty());  // global mode and the dynamic crop
  EXPECT_TRUE(st.horizon.active);
  // The walk's bob (2.6 m/s^2 at 1.8 Hz) puts many readings beyond 10 % of
  // 1 g: they are left out.
  EXPECT_GT(st.accel_accepted, 50u);
  EXPECT_GT(st.accel_rejected, 0u);
  EXPECT_LT(std::abs(st.horizon.output_roll_rad), 0.02);  // the walk is level
  ExpectAllFinite(sink);

  // The same without accelerometer readings: the roll is left alone.
  Sink bare;
  StabilizerWrapper w2(o, WrapperOptions(), &bare);
  Feed(&w2, TestStream(), 0, -1, [](sensor_msgs::Imu* m) {
    m->linear_acceleration.x = m->linear_acceleration.y =
        m->linear_acceleration.z = 0.0;
  });
  EXPECT_FALSE(w2.CurrentStatus().horizon.active);
  EXPECT_EQ(w2.CurrentStatus().horizon.inactive_reason, "no accelerometer");
  EXPECT_EQ(w2.CurrentStatus().counters.accel_in, 0u);
  EXPECT_EQ(bare.states.size(), TestStream().images.size());
}

// The composite with the dynamic crop runs, and the status says that they do
// not go together (the "view" diagnostic WARNs with it).
TEST(WrapperTest, TheCompositeWithTheDynamicCropIsNamedAConflict) {
  steadiface::PipelineOptions o = Options();
  o.warp.mode = steadiface::WarpMode::kComposite;
  o.crop.mode = steadiface::CropMode::kDynamic;
  Sink sink;
  StabilizerWrapper w(o, WrapperOptions(), &sink);
  Feed(&w, TestStream(), 0, 4);
  EXPECT_EQ(sink.images.size(), 4u);
  const std::string conflict = w.CurrentStatus().view_conflict;
  EXPECT_NE(conflict.find("output/crop fixed"), std::string::npos) << conflict;
  ExpectAllFinite(sink);
}

}  // namespace
}  // namespace wrapper_test
}  // namespace steadiface_ros
