// Face information extraction: ms/frame in tracking mode (gyro-predicted box,
// landmarks, checks, head pose) and in detection mode (full-frame
// detection + landmarks), on a rendered frame with the astronaut portrait
// as a billboard 0.45 m away, at 640x360, 1280x720 and 1920x1080.
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>

#include "steadiface_core/face/face_tracker.h"
#include "steadiface_core/sim/scene_renderer.h"

namespace steadiface {
namespace {

struct Scene {
  CameraModel model;
  cv::Mat frame;
};

Scene Make(int w, int h) {
  Scene s;
  CameraModel::Create(IntrinsicsFromHorizontalFov(w, h, 1.0), CameraModelOptions(), &s.model);
  const std::string data = STEADIFACE_TEST_DATA_DIR;
  const cv::Mat photo = cv::imread(data + "/astronaut.png");
  const sim::InfiniteBackground bg(cv::imread(data + "/building.jpg"), 600.0 * w / 640.0);
  sim::Billboard face =
      sim::MakeFaceBillboard(photo, cv::Rect(139, 38, 168, 188), 168 * 0.15 / 88.0);
  face.pose = [](double) {
    sim::Pose P;
    P.p = Eigen::Vector3d(0.02, 0.0, 0.45);
    return P;
  };
  sim::RenderScene(s.model.intrinsics(), [](double) { return 0.0; },
                   [](double) { return sim::Pose(); }, bg, {&face}, h, &s.frame);
  return s;
}

void Args(benchmark::internal::Benchmark* b) {
  b->Args({640, 360})->Args({1280, 720})->Args({1920, 1080});
  b->ArgNames({"w", "h"})->Unit(benchmark::kMillisecond);
}

void BM_FaceTracking(benchmark::State& state) {
  const Scene s = Make(state.range(0), state.range(1));
  FaceTrackerOptions o;
  o.redetect_every_frames = 10000;  // pure tracking
  std::unique_ptr<FaceTracker> t;
  const Status st = FaceTracker::Create(s.model, o, &t);
  if (!st.ok() || s.frame.empty()) {
    state.SkipWithError(st.ok() ? "no test frame" : st.message().c_str());
    return;
  }
  FaceInfo fi;
  double time = 1.0;
  t->Process(s.frame, Time(FromSeconds(time)), nullptr, nullptr, &fi);  // acquire
  for (auto _ : state) {
    time += 1.0 / 30;
    t->Process(s.frame, Time(FromSeconds(time)), nullptr, nullptr, &fi);
  }
  state.counters["valid"] = fi.valid;
  state.counters["detected"] = fi.detected;
}

void BM_FaceDetectionMode(benchmark::State& state) {
  const Scene s = Make(state.range(0), state.range(1));
  std::unique_ptr<FaceTracker> t;
  const Status st = FaceTracker::Create(s.model, FaceTrackerOptions(), &t);
  if (!st.ok() || s.frame.empty()) {
    state.SkipWithError(st.ok() ? "no test frame" : st.message().c_str());
    return;
  }
  FaceInfo fi;
  for (auto _ : state) {
    t->reset();  // forces full-frame detection + landmarks
    t->Process(s.frame, Time(FromSeconds(1.0)), nullptr, nullptr, &fi);
  }
  state.counters["valid"] = fi.valid;
}

// Tracking with the default periodic re-detection (every 15 frames, near the
// face): the amortized per-frame cost.
void BM_FaceTrackingWithRedetection(benchmark::State& state) {
  const Scene s = Make(state.range(0), state.range(1));
  std::unique_ptr<FaceTracker> t;
  const Status st = FaceTracker::Create(s.model, FaceTrackerOptions(), &t);
  if (!st.ok() || s.frame.empty()) {
    state.SkipWithError(st.ok() ? "no test frame" : st.message().c_str());
    return;
  }
  FaceInfo fi;
  double time = 1.0;
  t->Process(s.frame, Time(FromSeconds(time)), nullptr, nullptr, &fi);
  for (auto _ : state) {
    time += 1.0 / 30;
    t->Process(s.frame, Time(FromSeconds(time)), nullptr, nullptr, &fi);
  }
  state.counters["valid"] = fi.valid;
}

BENCHMARK(BM_FaceTracking)->Apply(Args);
BENCHMARK(BM_FaceTrackingWithRedetection)->Apply(Args);
BENCHMARK(BM_FaceDetectionMode)->Apply(Args);

}  // namespace
}  // namespace steadiface

BENCHMARK_MAIN();
