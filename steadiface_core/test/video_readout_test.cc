// The rolling-shutter readout from the video alone (no IMU): on rendered
// walking selfies whose readout is known, and on a still camera, which
// cannot determine it.
#include "steadiface_core/calibration/video_readout.h"

#include <iostream>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim_util.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;

// `hand_waved`: the camera waved by hand at 2-4 Hz, 1.7 deg RMS (a
// calibration recording) instead of the preset's shake.
VideoReadoutResult EstimateOn(const std::string& preset, double readout_s, double duration_s,
                              bool hand_waved = false) {
  auto s = MakeSimulator(preset, [&](sim::SimulatorOptions* o) {
    o->readout_s = readout_s;
    o->duration_s = duration_s;
    if (hand_waved) {
      o->camera.shake_lo_hz = 2.0;
      o->camera.shake_hi_hz = 4.0;
      o->camera.shake_rms_rad = 0.03;
    }
  });
  std::unique_ptr<VideoReadoutEstimator> e;
  RollingShutterOptions rs;  // first-row stamps, as the simulator's
  EXPECT_TRUE(VideoReadoutEstimator::Create(s->intrinsics(), rs, {}, &e).ok());
  cv::Mat frame, grey;
  sim::SimTruth t;
  for (int i = 0; i < s->num_frames(); ++i) {
    EXPECT_TRUE(s->Render(i, &frame, &t).ok());
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    EXPECT_TRUE(e->AddFrame(grey, t.stamp).ok());
  }
  const VideoReadoutResult r = e->Estimate();
  std::cout << "[ " << preset << (hand_waved ? " waved" : "") << ", readout " << readout_s * 1e3 << " ms ] estimate "
            << r.readout_s * 1e3 << " ms +- " << r.sigma_s * 1e3 << " (" << r.triples
            << " triples, correlation " << r.correlation << ")"
            << (r.determined ? "" : ": not determined, " + r.reason) << "\n";
  return r;
}

// Waved by hand at 2-4 Hz, 4 s (measured: 10.7, 20.4, 29.7 ms).
TEST(VideoReadoutTest, TheReadoutOfAWavedCameraFromTheVideoAlone) {
  for (double readout : {0.01, 0.02, 0.03}) {
    const VideoReadoutResult r = EstimateOn("walk", readout, 4.0, true);
    EXPECT_TRUE(r.determined) << r.reason;
    EXPECT_NEAR(r.readout_s, readout, 0.0015);
  }
}

// The walking selfie's shake (0.7 deg RMS up to 12 Hz): the low-passed part
// is smaller against the noise (measured: 10.4 and 20.2 ms; at 30 ms
// 28.4 +- 1.9 ms, correlation 0.67). Determined or not, never far off.
TEST(VideoReadoutTest, AWalkingSelfieDeterminesItOrSaysItCannot) {
  for (double readout : {0.01, 0.02, 0.03}) {
    const VideoReadoutResult r = EstimateOn("walk", readout, 4.0);
    if (readout < 0.025) EXPECT_TRUE(r.determined) << r.reason;
    if (r.determined) EXPECT_NEAR(r.readout_s, readout, 0.002);
  }
}

TEST(VideoReadoutTest, AStillCameraDoesNotDetermineIt) {
  const VideoReadoutResult r = EstimateOn("still", 0.02, 2.0);
  EXPECT_FALSE(r.determined);
  EXPECT_FALSE(r.reason.empty());
}

}  // namespace
}  // namespace steadiface
