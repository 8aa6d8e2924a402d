// Stabilizer benchmarks: head smoothing (Eq. 1) and the per-frame Ceres
// solve on a simulated walking selfie (68 landmarks, 20 ms rolling shutter).
// Reported counters: solver median / p99 [ms] and median iterations.
#include <algorithm>
#include <vector>

#include <benchmark/benchmark.h>

#include "steadiface_core/common/percentile.h"

#include "steadiface_core/sim/landmark_sequence.h"
#include "steadiface_core/stabilizer/stabilizer.h"

namespace steadiface {
namespace {

void BM_HeadSmoother(benchmark::State& state) {
  HeadSmoother hs{HeadSmootherOptions()};
  Eigen::Vector2d H(0.5, 0.5);
  double k = 0.0;
  for (auto _ : state) {
    k += 0.01;
    H = hs.Solve(H, Eigen::Vector2d(0.5 + 0.01 * std::sin(k), 0.5), {0.1, 0.056});
    benchmark::DoNotOptimize(H);
  }
}
BENCHMARK(BM_HeadSmoother);

// One iteration = one whole sequence; per-frame figures as counters.
void BM_StabilizerPerFrame(benchmark::State& state) {
  const bool gyro_only = state.range(0) != 0;
  CameraModel m;
  if (!CameraModel::Create(IntrinsicsFromHorizontalFov(1280, 720, 1.2), CameraModelOptions(), &m)
           .ok()) {
    state.SkipWithError("no camera model");
    return;
  }
  sim::LandmarkSequenceOptions o;
  o.duration_s = 4.0;
  o.camera.shake_rms_rad = 0.012;
  o.shutter.readout_time_s = 0.02;
  o.landmark_noise_px = 1.0;
  const sim::LandmarkSequence seq(m, o);
  std::vector<double> solve_ms, total_ms, iterations;
  for (auto _ : state) {
    state.PauseTiming();
    std::unique_ptr<Stabilizer> stab;
    StabilizerOptions so;
    so.gyro_only = gyro_only;
    if (!Stabilizer::Create(m, OutputOptions(), so, &stab).ok()) {
      state.SkipWithError("no stabilizer");
      break;
    }
    OrientationTimeline tl{OrientationTimelineOptions()};
    size_t g = 0;
    state.ResumeTiming();
    for (const auto& fr : seq.frames()) {
      while (g < seq.gyro().size() &&
             seq.gyro()[g].stamp <= seq.timing().LastRowTime(fr.stamp) + FromSeconds(0.006)) {
        tl.AddSample(seq.gyro()[g++]);
      }
      StabilizerFrame out;
      if (!stab->Process(fr.stamp, tl, seq.timing(), &fr.observed, &out).ok()) continue;
      solve_ms.push_back(out.solver.time_ms);
      total_ms.push_back(out.timings.total_ms);
      iterations.push_back(out.solver.iterations);
    }
  }
  state.counters["solver_median_ms"] = Percentile(solve_ms, 0.5);
  state.counters["solver_p99_ms"] = Percentile(solve_ms, 0.99);
  state.counters["frame_median_ms"] = Percentile(total_ms, 0.5);
  state.counters["frame_p99_ms"] = Percentile(total_ms, 0.99);
  state.counters["iterations_median"] = Percentile(iterations, 0.5);
  state.counters["frames"] = static_cast<double>(seq.frames().size());
}
BENCHMARK(BM_StabilizerPerFrame)->Arg(0)->Arg(1)->ArgName("gyro_only")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace steadiface

BENCHMARK_MAIN();
