// End to end per frame (issue: performance): Pipeline::ProcessFrame on
// rendered walking-selfie frames with the face present (tracking mode with
// the default periodic re-detection, amortized), i.e. landmarks + head
// smoothing + Ceres solve + rolling-shutter mesh + maps + remap, at 640x360,
// 1280x720 and 1920x1080, on 1 and 2 threads. Acquisition (the first
// full-frame detection) is outside the timed loop. Counters: median stage
// times over the timed frames. The fourth argument picks the warp mode
// (0 global, 1 layered: both layers' meshes and the band's optimization;
// 2 composite: both layers' pictures, the matte, the plate and the blend);
// the fifth the rotation source (0 the IMU, 1 the video: visual_ms is the
// visual source's median).
#include <algorithm>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "steadiface_core/common/percentile.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"
#include "walk_frames.h"

namespace steadiface {
namespace {

constexpr int kFrames = 60;

using Sequence = bench::WalkFrames;

const Sequence& Get(int w, int h) { return bench::GetWalkFrames(w, h, kFrames); }

// The benchmark's options: the method's, with the warp threads, the warp
// mode (0 global, 1 layered, 2 composite), the rotation source (1 visual)
// and the view (1: dynamic crop and level horizon) of the arguments 2-5.
PipelineOptions BenchOptions(const Sequence& seq, const benchmark::State& state) {
  PipelineOptions po = eval::OptionsFor(*seq.sim, eval::Method::kSteadiface);
  po.render_output = true;
  po.warp.num_threads = static_cast<int>(state.range(2));
  if (state.range(3) == 1) po.warp.mode = WarpMode::kLayered;
  if (state.range(3) == 2) po.warp.mode = WarpMode::kComposite;
  if (state.range(4) == 1) po.rotation_source = RotationSource::kVisual;
  if (state.range(5) == 1) {
    po.crop.mode = CropMode::kDynamic;
    po.horizon.mode = HorizonMode::kLevel;
  }
  return po;
}

// Each stage's time per frame, and the counters they give.
struct StageTimes {
  std::vector<double> face, stab, warp, mesh, composite, matte, plate, blend, total, visual, crop;
  double check_sum = 0.0, check_max = 0.0;

  void Add(const PipelineFrame& out) {
    face.push_back(out.timings.face_ms);
    stab.push_back(out.timings.stabilizer_ms);
    warp.push_back(out.timings.mesh_ms + out.timings.maps_ms + out.timings.remap_ms);
    mesh.push_back(out.timings.mesh_ms);
    composite.push_back(out.timings.composite_ms);
    matte.push_back(out.composite.report.matte_ms);
    plate.push_back(out.composite.report.plate_ms);
    blend.push_back(out.composite.report.blend_ms);
    total.push_back(out.timings.total_ms);
    visual.push_back(out.visual.ms);
    crop.push_back(out.timings.crop_ms);
    check_sum += out.timings.check_ms;
    check_max = std::max(check_max, out.timings.check_ms);
  }

  void Report(benchmark::State& state) const {
    state.counters["face_ms"] = Percentile(face, 0.5);
    state.counters["stabilizer_ms"] = Percentile(stab, 0.5);
    state.counters["warp_ms"] = Percentile(warp, 0.5);
    state.counters["mesh_ms"] = Percentile(mesh, 0.5);
    state.counters["composite_ms"] = Percentile(composite, 0.5);
    state.counters["matte_ms"] = Percentile(matte, 0.5);
    state.counters["plate_ms"] = Percentile(plate, 0.5);
    state.counters["blend_ms"] = Percentile(blend, 0.5);
    state.counters["visual_ms"] = Percentile(visual, 0.5);
    state.counters["crop_ms"] = Percentile(crop, 0.5);
    // The gyro-vs-video check runs on one frame pair in `stride`: its mean
    // per frame, and the checked frames' cost.
    state.counters["check_mean_ms"] = total.empty() ? 0.0 : check_sum / total.size();
    state.counters["check_max_ms"] = check_max;
    // The headline target is a median (the reported time is a mean, which
    // includes the periodic re-detection frames).
    state.counters["total_p50_ms"] = Percentile(total, 0.5);
  }
};

void BM_PipelineFrame(benchmark::State& state) {
  const Sequence& seq = Get(state.range(0), state.range(1));
  if (seq.frames.size() < 10) {
    state.SkipWithError("could not render the sequence");
    return;
  }
  const PipelineOptions po = BenchOptions(seq, state);
  std::unique_ptr<Pipeline> p;
  size_t g = 0, i = 0;
  StageTimes times;
  // A fresh pipeline that has acquired the face on the first frame.
  auto restart = [&]() -> bool {
    if (!Pipeline::Create(seq.sim->intrinsics(), po, &p).ok()) return false;
    g = 0;
    i = 0;
    return true;
  };
  auto feed = [&](size_t k, PipelineFrame* out) {
    const Time stamp = seq.sim->Truth(static_cast<int>(k)).stamp;
    eval::FeedGyroForFrame(*seq.sim, stamp, po.imu.imu_time_offset_s, p.get(), &g);
    return p->ProcessFrame(seq.frames[k], stamp, nullptr, 0.0, out);
  };
  PipelineFrame out;
  if (!restart()) {
    state.SkipWithError("pipeline refused its options");
    return;
  }
  if (const Status first = feed(i++, &out); !first.ok()) {
    state.SkipWithError(("pipeline refused the first frame: " + first.message()).c_str());
    return;
  }
  for (auto _ : state) {
    if (i == seq.frames.size()) {
      state.PauseTiming();
      if (!restart() || !feed(i++, &out).ok()) {
        state.SkipWithError("pipeline refused a restart");
        break;
      }
      state.ResumeTiming();
    }
    const Status s = feed(i++, &out);
    if (!s.ok()) {
      state.SkipWithError(s.message().c_str());
      break;
    }
    times.Add(out);
  }
  times.Report(state);
  state.counters["face_valid"] = out.face.valid;
}

BENCHMARK(BM_PipelineFrame)
    ->Args({640, 360, 1, 0, 0, 0})
    ->Args({1280, 720, 1, 0, 0, 0})
    ->Args({1920, 1080, 1, 0, 0, 0})
    ->Args({640, 360, 2, 0, 0, 0})
    ->Args({1280, 720, 2, 0, 0, 0})
    ->Args({1920, 1080, 2, 0, 0, 0})
    ->Args({640, 360, 1, 1, 0, 0})
    ->Args({1280, 720, 1, 1, 0, 0})
    ->Args({1920, 1080, 1, 1, 0, 0})
    ->Args({640, 360, 1, 2, 0, 0})
    ->Args({1280, 720, 1, 2, 0, 0})
    ->Args({1920, 1080, 1, 2, 0, 0})
    ->Args({1280, 720, 2, 2, 0, 0})
    ->Args({1920, 1080, 2, 2, 0, 0})
    ->Args({640, 360, 1, 0, 1, 0})
    ->Args({1280, 720, 1, 0, 1, 0})
    ->Args({1920, 1080, 1, 0, 1, 0})
    // The view: the dynamic crop and the level horizon, against the same
    // size and mode with neither (view 0).
    ->Args({1280, 720, 1, 0, 0, 1})
    ->Args({1280, 720, 1, 1, 0, 1})
    ->ArgNames({"w", "h", "threads", "mode", "rotation", "view"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace steadiface

BENCHMARK_MAIN();
