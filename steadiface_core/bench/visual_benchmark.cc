// The rotation from the video (visual/visual_rotation.h) on its own:
// VisualRotationEstimator::Process per frame of a rendered walking selfie
// (grey frames, the face box given as the pipeline gives it), one core, at
// 640x360, 1280x720 and 1920x1080. The time is the mean per frame; the
// counters are the median and the 90th percentile, and the share of
// trusted estimates. The second argument is the work per frame: 0 the
// whole estimate, 1 only the grey copy it tracks on (the resize).
#include <chrono>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/percentile.h"
#include "steadiface_core/sim/simulator.h"
#include "steadiface_core/visual/visual_rotation.h"
#include "walk_frames.h"

namespace steadiface {
namespace {

constexpr int kFrames = 40;

struct Frames {
  const sim::Simulator* sim = nullptr;
  std::vector<cv::Mat> grey;
  std::vector<cv::Rect2d> faces;
};

const Frames& Get(int w, int h) {
  static std::vector<std::pair<std::pair<int, int>, Frames>> cache;
  for (auto& c : cache) {
    if (c.first == std::make_pair(w, h)) return c.second;
  }
  const bench::WalkFrames& walk = bench::GetWalkFrames(w, h, kFrames);
  Frames f;
  f.sim = walk.sim.get();
  for (size_t i = 0; i < walk.frames.size(); ++i) {
    cv::Mat grey;
    cv::cvtColor(walk.frames[i], grey, cv::COLOR_BGR2GRAY);
    f.grey.push_back(grey);
    const sim::SimTruth& truth = walk.truth[i];
    const double s = truth.face_scale_px;
    f.faces.push_back(truth.head_in_view ? cv::Rect2d(truth.head_px.x() - 0.5 * s,
                                                      truth.head_px.y() - 0.6 * s, s, 1.2 * s)
                                         : cv::Rect2d());
  }
  cache.emplace_back(std::make_pair(w, h), std::move(f));
  return cache.back().second;
}

void BM_VisualRotation(benchmark::State& state) {
  const Frames& f = Get(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  cv::setNumThreads(1);
  CameraModel model;
  std::unique_ptr<VisualRotationEstimator> est;
  if (f.grey.size() < 2 || !CameraModel::Create(f.sim->intrinsics(), {}, &model).ok() ||
      !VisualRotationEstimator::Create(model, f.sim->timing(), {}, &est).ok()) {
    state.SkipWithError("no frames");
    return;
  }
  std::vector<double> ms;
  int valid = 0, n = 0;
  size_t i = 0;
  for (auto _ : state) {
    VisualRotation r;
    const auto t0 = std::chrono::steady_clock::now();
    if (state.range(2) == 1) {
      cv::Mat small;
      cv::resize(f.grey[i], small, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
      benchmark::DoNotOptimize(small.data);
    } else if (!est->Process(f.grey[i], f.sim->Truth(static_cast<int>(i)).stamp, f.faces[i], &r)
                    .ok()) {
      state.SkipWithError("Process failed");
      return;
    }
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                     .count());
    valid += r.valid ? 1 : 0;
    ++n;
    if (++i == f.grey.size()) {  // a new pass starts with no previous frame
      i = 0;
      est->Reset();
    }
  }
  state.counters["p50_ms"] = Percentile(ms, 0.5);
  state.counters["p90_ms"] = Percentile(ms, 0.9);
  state.counters["trusted"] = n ? static_cast<double>(valid) / n : 0.0;
}

BENCHMARK(BM_VisualRotation)
    ->Args({640, 360, 0})
    ->Args({1280, 720, 0})
    ->Args({1920, 1080, 0})
    ->Args({1280, 720, 1})
    ->ArgNames({"w", "h", "copy_only"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace steadiface

BENCHMARK_MAIN();
