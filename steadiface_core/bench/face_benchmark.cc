// Face information extraction: ms/frame in tracking mode (gyro-predicted box,
// landmarks, checks, head pose) and in detection mode (full-frame
// detection + landmarks), on a rendered frame with the astronaut portrait
// as a billboard 0.45 m away, at 640x360, 1280x720 and 1920x1080; and a
// robot's view (640x480, 60 deg): the face 2.75 m away, 30 px wide, tracked,
// and the search with nobody in view, with and without the small-face tiles;
// and a head followed past the landmarks (face/head_turn.h): its region's
// tracks and the turning cylinder's update.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/face/face_tracker.h"
#include "steadiface_core/face/head_region_motion.h"
#include "steadiface_core/face/head_turn.h"
#include "steadiface_core/sim/scene_renderer.h"

namespace steadiface {
namespace {

struct Scene {
  CameraModel model;
  cv::Mat frame;
};

// `distance_m` < 0: no face.
Scene Make(int w, int h, double hfov = 1.0, double distance_m = 0.45) {
  Scene s;
  if (!CameraModel::Create(IntrinsicsFromHorizontalFov(w, h, hfov), CameraModelOptions(), &s.model)
           .ok()) {
    return s;  // no frame: the benchmark skips
  }
  const std::string data = STEADIFACE_TEST_DATA_DIR;
  const cv::Mat photo = cv::imread(data + "/astronaut.png");
  const sim::InfiniteBackground bg(cv::imread(data + "/building.jpg"), 600.0 * w / 640.0);
  sim::Billboard face =
      sim::MakeFaceBillboard(photo, cv::Rect(139, 38, 168, 188), 168 * 0.15 / 88.0);
  face.pose = [distance_m](double) {
    sim::Pose P;
    P.p = Eigen::Vector3d(0.02 * distance_m / 0.45, 0.0, distance_m);
    return P;
  };
  std::vector<const sim::Billboard*> boards;
  if (distance_m > 0.0) boards.push_back(&face);
  sim::RenderScene(s.model.intrinsics(), [](double) { return 0.0; },
                   [](double) { return sim::Pose(); }, bg, boards, h, &s.frame);
  return s;
}

void Args(benchmark::internal::Benchmark* b) {
  b->Args({640, 360})->Args({1280, 720})->Args({1920, 1080});
  b->ArgNames({"w", "h"})->Unit(benchmark::kMillisecond);
}

// One frame through the tracker; false (and the benchmark skipped) on an
// error.
bool Track(FaceTracker* t, const Scene& s, double time, FaceInfo* fi, benchmark::State& state) {
  const Status st = t->Process(s.frame, Time(FromSeconds(time)), nullptr, nullptr, fi);
  if (!st.ok()) state.SkipWithError(st.message().c_str());
  return st.ok();
}

// The tracker for `s`; null (and the benchmark skipped) when it cannot be made.
std::unique_ptr<FaceTracker> MakeTracker(const Scene& s, const FaceTrackerOptions& o,
                                         benchmark::State& state) {
  std::unique_ptr<FaceTracker> t;
  const Status st = FaceTracker::Create(s.model, o, &t);
  if (!st.ok() || s.frame.empty()) {
    state.SkipWithError(st.ok() ? "no test frame" : st.message().c_str());
    return nullptr;
  }
  return t;
}

// The face acquired on the first frame, then tracked at 30 fps.
void TrackAt30Fps(benchmark::State& state, const FaceTrackerOptions& o) {
  const Scene s = Make(state.range(0), state.range(1));
  const std::unique_ptr<FaceTracker> t = MakeTracker(s, o, state);
  if (!t) return;
  FaceInfo fi;
  double time = 1.0;
  if (!Track(t.get(), s, time, &fi, state)) return;  // acquire
  for (auto _ : state) {
    time += 1.0 / 30;
    if (!Track(t.get(), s, time, &fi, state)) break;
  }
  state.counters["valid"] = fi.valid;
  state.counters["detected"] = fi.detected;
}

void BM_FaceTracking(benchmark::State& state) {
  FaceTrackerOptions o;
  o.redetect_every_frames = 10000;  // pure tracking
  TrackAt30Fps(state, o);
}

void BM_FaceDetectionMode(benchmark::State& state) {
  const Scene s = Make(state.range(0), state.range(1));
  const std::unique_ptr<FaceTracker> t = MakeTracker(s, FaceTrackerOptions(), state);
  if (!t) return;
  FaceInfo fi;
  for (auto _ : state) {
    t->Reset();  // forces full-frame detection + landmarks
    if (!Track(t.get(), s, 1.0, &fi, state)) break;
  }
  state.counters["valid"] = fi.valid;
}

// Tracking with the default periodic re-detection (every 15 frames, near the
// face): the amortized per-frame cost.
void BM_FaceTrackingWithRedetection(benchmark::State& state) {
  TrackAt30Fps(state, FaceTrackerOptions());
}

// The robot's view: a 30 px face, tracked with the default re-detection
// (upsampled near the face) and landmarks on an upsampled crop.
void BM_SmallFaceTracking(benchmark::State& state) {
  const Scene s = Make(640, 480, M_PI / 3.0, 2.75);
  const std::unique_ptr<FaceTracker> t = MakeTracker(s, FaceTrackerOptions(), state);
  if (!t) return;
  FaceInfo fi;
  double time = 1.0;
  for (int i = 0; i < 10 && !fi.valid; ++i, time += 1.0 / 30) {  // acquire
    if (!Track(t.get(), s, time, &fi, state)) return;
  }
  if (!fi.valid) {
    state.SkipWithError("the 30 px face was not acquired");
    return;
  }
  int valid = 0, n = 0;
  for (auto _ : state) {
    time += 1.0 / 30;
    if (!Track(t.get(), s, time, &fi, state)) break;
    valid += fi.valid ? 1 : 0;
    ++n;
  }
  state.counters["face_px"] = fi.valid ? fi.box.width : 0.0;
  state.counters["valid"] = static_cast<double>(valid) / std::max(1, n);
}

// Nobody in view at 30 fps: the mean cost per frame of the search (the
// whole frame every 0.1 s, a small-face tile half-way between); min_face:0
// is the tracker's default (30 px), 80 drops the tiles.
void BM_SearchWithNobodyInView(benchmark::State& state) {
  const Scene s = Make(state.range(0), state.range(1), M_PI / 3.0, -1.0);
  FaceTrackerOptions o;
  if (state.range(2) > 0) o.detector.min_face_px = static_cast<int>(state.range(2));
  const std::unique_ptr<FaceTracker> t = MakeTracker(s, o, state);
  if (!t) return;
  FaceInfo fi;
  double time = 1.0, worst = 0.0;
  for (auto _ : state) {
    time += 1.0 / 30;
    if (!Track(t.get(), s, time, &fi, state)) break;
    worst = std::max(worst, fi.timings.total_ms);
  }
  state.counters["worst_ms"] = worst;
}

// One followed frame's own cost (the landmarks are still tried in the box,
// as BM_FaceTracking costs): the head region's KLT tracks into the next
// frame (the picture moved by 2.5, 1.5 px) and the cylinder's update.
void BM_FollowTurnedHead(benchmark::State& state) {
  const Scene s = Make(state.range(0), state.range(1));
  const std::unique_ptr<FaceTracker> t = MakeTracker(s, FaceTrackerOptions(), state);
  if (!t) return;
  FaceInfo fi;
  if (!Track(t.get(), s, 1.0, &fi, state)) return;
  if (!fi.valid) {
    state.SkipWithError("the face was not acquired");
    return;
  }
  cv::Mat grey, moved;
  cv::cvtColor(s.frame, grey, cv::COLOR_BGR2GRAY);
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, 2.5, 0, 1, 1.5);
  cv::warpAffine(grey, moved, M, grey.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  HeadRegionMotion motion;
  motion.Remember(grey, fi.box);
  RegionFlow flow;
  double tracks = 0.0;
  for (auto _ : state) {
    HeadTurn head;
    head.radius_px = 1.5 * fi.scale_px;
    head.axis_px = fi.centre_px;
    if (!motion.Track(moved, &flow) || !UpdateHeadTurn(flow, &head)) {
      state.SkipWithError("the head region was not followed");
      break;
    }
    tracks = static_cast<double>(flow.shift.size());
    benchmark::DoNotOptimize(head);
  }
  state.counters["tracks"] = tracks;
  state.counters["face_px"] = fi.box.width;
}

BENCHMARK(BM_FaceTracking)->Apply(Args);
BENCHMARK(BM_FollowTurnedHead)->Apply(Args);
BENCHMARK(BM_SmallFaceTracking)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SearchWithNobodyInView)
    ->Args({640, 480, 0})
    ->Args({640, 480, 80})
    ->Args({1280, 720, 0})
    ->Args({1280, 720, 160})
    ->ArgNames({"w", "h", "min_face"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FaceTrackingWithRedetection)->Apply(Args);
BENCHMARK(BM_FaceDetectionMode)->Apply(Args);

}  // namespace
}  // namespace steadiface

BENCHMARK_MAIN();
