// The face tracker under strong shake, on the simulator's
// `shake` preset: the recorded running gyro trace at 3x, a grey picture,
// 25 ms exposure blur and a 30 ms rolling shutter. The face must be tracked
// on >= 95 % of the frames in which it is fully visible, and on every frame
// in which an independent full-frame detection finds it (the tracker must
// never drop a face a fresh detection would find). Before the fix (the
// lost state relied on detection alone, at one scale) it was 113 of 120
// visible frames.
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/face/face_detector.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

TEST(TrackingUnderShakeTest, EveryVisibleFaceIsTracked) {
  sim::SimulatorOptions so;
  ASSERT_TRUE(sim::ApplyPreset("shake", &so).ok());
  so.data_dir = STEADIFACE_TEST_DATA_DIR;
  so.duration_s = 9.0;
  std::unique_ptr<sim::Simulator> sim;
  ASSERT_TRUE(sim::Simulator::Create(so, &sim).ok());
  const PipelineOptions po = eval::OptionsFor(*sim, eval::Method::kSteadiface);
  std::unique_ptr<Pipeline> p;
  ASSERT_TRUE(Pipeline::Create(sim->intrinsics(), po, &p).ok());
  std::unique_ptr<FaceDetector> fresh_detector;
  ASSERT_TRUE(
      FaceDetector::Create(FaceDetectorOptions(), &fresh_detector).ok());
  int visible = 0, tracked = 0, found = 0, tracked_found = 0;
  std::map<std::string, int> reasons;
  size_t g = 0;
  cv::Mat frame, grey;
  sim::SimTruth truth;
  for (int i = 0; i < sim->num_frames(); ++i) {
    eval::FeedGyroForFrame(*sim, sim->Truth(i).stamp, po.imu.imu_time_offset_s,
                           p.get(), &g);
    ASSERT_TRUE(sim->Render(i, &frame, &truth).ok());
    PipelineFrame out;
    ASSERT_TRUE(p->ProcessFrame(frame, truth.stamp, nullptr, 0.0, &out).ok());
    // Fully visible: the whole face (0.8 face widths around the centre)
    // inside the frame and not occluded; after the first acquisition.
    const double r = 0.8 * truth.face_scale_px;
    const bool full = truth.head_in_view && !truth.occluded &&
                      truth.head_px.x() > r && truth.head_px.y() > r &&
                      truth.head_px.x() + r < frame.cols &&
                      truth.head_px.y() + r < frame.rows;
    if (!full || i < 5) continue;
    ++visible;
    if (out.face.valid) {
      ++tracked;
    } else {
      ++reasons[FaceFailureName(out.face.failure)];
    }
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    std::vector<FaceBox> faces;
    ASSERT_TRUE(fresh_detector
                    ->Detect(grey, cv::Rect(0, 0, grey.cols, grey.rows), &faces)
                    .ok());
    for (const FaceBox& f : faces) {
      const Eigen::Vector2d c(f.rect.x + 0.5 * f.rect.width,
                              f.rect.y + 0.5 * f.rect.height);
      if ((c - truth.head_px).norm() < truth.face_scale_px) {
        ++found;
        if (out.face.valid) {
          ++tracked_found;
        } else {
          ADD_FAILURE() << "frame " << i
                        << ": a fresh detection finds the face, the tracker "
                        << "dropped it (" << FaceFailureName(out.face.failure)
                        << ")";
        }
        break;
      }
    }
  }
  std::cout << "  shake: tracked " << tracked << " of " << visible
            << " fully visible frames; a fresh detection finds " << found
            << ", tracked " << tracked_found << " of those; losses:";
  for (const auto& kv : reasons)
    std::cout << " " << kv.first << " " << kv.second;
  std::cout << "\n";
  ASSERT_GT(visible, 60);
  // Every frame a fresh detection finds is tracked. Of the others, the few
  // smeared hardest by the shake may be declined: their eye and mouth rows,
  // read out at different times, are blurred differently, and the
  // per-region appearance check then takes them for a partly covered face
  // (117 of 120 tracked here; 119 before that check). The relief head
  // (2026-11-26) also turns and nods, which the regions show unequally:
  // 129 of 131 on Debian 12, 126 of 131 on Debian 11's dlib and OpenCV.
  EXPECT_GE(tracked, 0.95 * visible);
  EXPECT_EQ(tracked_found, found);
}

}  // namespace
}  // namespace steadiface
