// Warp stage benchmarks (issue: mesh warping). Arguments: width, height,
// channels (1 = mono8, 3 = bgr8), threads.
//   devel/lib/steadiface/steadiface_warp_benchmark
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/warp/mesh_sampler.h"
#include "steadiface_core/warp/warper.h"

namespace steadiface {
namespace {

// False (and the benchmark skipped) when `s` is an error.
bool Ok(const Status& s, benchmark::State& state) {
  if (!s.ok()) state.SkipWithError(s.message().c_str());
  return s.ok();
}

struct Fixture {
  Status status;  ///< of the set-up
  CameraModel model;
  std::unique_ptr<Warper> warper;
  cv::Mat input, output;
  RowRotations rows;
  Eigen::Quaterniond R_v;
  Eigen::Vector2d t{0.01, -0.005};

  Fixture(int w, int h, int channels, int threads, bool direct = true) {
    status = CameraModel::Create(IntrinsicsFromHorizontalFov(w, h, 1.2), CameraModelOptions(),
                                 &model);
    WarpOptions o;
    o.num_threads = threads;
    o.direct_sampling = direct;
    if (status.ok()) status = Warper::Create(model, o, &warper);
    if (!status.ok()) return;
    input.create(h, w, channels == 1 ? CV_8UC1 : CV_8UC3);
    cv::randu(input, cv::Scalar::all(0), cv::Scalar::all(255));
    // A rolling-shutter frame: 25 mrad of rotation over the readout.
    OrientationTimeline tl{OrientationTimelineOptions()};
    for (int i = 0; i <= 100; ++i) {
      tl.AddSample({Time(FromSeconds(i * 0.001)), Eigen::Vector3d(0.3, 0.8, 0.1)});
    }
    RollingShutterOptions rs;
    rs.readout_time_s = 0.03;
    if (RowRotations::Build(tl, RowTiming(rs, h), Time(FromSeconds(0.02)), 32, &rows) !=
        QueryResult::kOk) {
      status = Status::Error("no row rotations");
    }
    R_v = rows.Middle() * ExpSO3(Eigen::Vector3d(0.005, -0.01, 0.002));
  }
};

void Args(benchmark::internal::Benchmark* b) {
  for (int threads : {1, 2}) {
    for (auto wh : {std::make_pair(640, 480), std::make_pair(1280, 720),
                    std::make_pair(1920, 1080)}) {
      for (int ch : {3, 1}) b->Args({wh.first, wh.second, ch, threads});
    }
  }
  b->ArgNames({"w", "h", "ch", "threads"})->Unit(benchmark::kMillisecond);
}

void BM_Mesh(benchmark::State& state) {
  Fixture f(state.range(0), state.range(1), state.range(2), state.range(3));
  if (!Ok(f.status, state)) return;
  for (auto _ : state) {
    if (!Ok(f.warper->ComputeMesh(f.R_v, f.t, f.rows), state)) break;
  }
}

void BM_Maps(benchmark::State& state) {
  Fixture f(state.range(0), state.range(1), state.range(2), state.range(3), false);
  if (!Ok(f.status, state) || !Ok(f.warper->ComputeMesh(f.R_v, f.t, f.rows), state)) return;
  for (auto _ : state) f.warper->BuildMaps();
}

void BM_Remap(benchmark::State& state) {
  Fixture f(state.range(0), state.range(1), state.range(2), state.range(3), false);
  if (!Ok(f.status, state) || !Ok(f.warper->ComputeMesh(f.R_v, f.t, f.rows), state)) return;
  f.warper->BuildMaps();
  for (auto _ : state) {
    if (!Ok(f.warper->Remap(f.input, &f.output), state)) break;
  }
}

// The warp kernel: the mesh sampled directly (SampleMesh), no maps.
void BM_DirectSample(benchmark::State& state) {
  Fixture f(state.range(0), state.range(1), state.range(2), state.range(3));
  if (!Ok(f.status, state) || !Ok(f.warper->ComputeMesh(f.R_v, f.t, f.rows), state)) return;
  for (auto _ : state) {
    if (!Ok(f.warper->Render(f.input, &f.output), state)) break;
  }
}

// The same mesh through the portable kernel only (SampleKernel::kPortable):
// the A/B of the shuffle kernels (bgr8, mono8) in one binary. Reports the
// share of pixels the shuffle kernels took in the default path as the
// counter "shuffle_share".
void BM_DirectSamplePortable(benchmark::State& state) {
  Fixture f(state.range(0), state.range(1), state.range(2), state.range(3));
  if (!Ok(f.status, state) || !Ok(f.warper->ComputeMesh(f.R_v, f.t, f.rows), state)) return;
  const cv::Size out(f.warper->output_geometry().width(),
                     f.warper->output_geometry().height());
  SampleStats st;
  SampleMesh(f.warper->mesh(), f.input, out.width, out.height, &f.output,
             SampleKernel::kAuto, &st);
  for (auto _ : state) {
    SampleMesh(f.warper->mesh(), f.input, out.width, out.height, &f.output,
               SampleKernel::kPortable);
  }
  state.counters["shuffle_share"] =
      static_cast<double>(st.shuffle_px) / static_cast<double>(out.area());
}

// Mesh + direct sampling (the default).
void BM_WarpEndToEnd(benchmark::State& state) {
  Fixture f(state.range(0), state.range(1), state.range(2), state.range(3));
  if (!Ok(f.status, state)) return;
  for (auto _ : state) {
    if (!Ok(f.warper->Warp(f.input, f.R_v, f.t, f.rows, &f.output), state)) break;
  }
}

// The floor: a bare cv::remap with precomputed float maps.
void BM_BareRemapFloor(benchmark::State& state) {
  Fixture f(state.range(0), state.range(1), state.range(2), state.range(3));
  if (!Ok(f.status, state) || !Ok(f.warper->ComputeMesh(f.R_v, f.t, f.rows), state)) return;
  f.warper->BuildMaps();
  cv::Mat mx, my, m1, m2;
  f.warper->FloatMaps(&mx, &my);
  cv::convertMaps(mx, my, m1, m2, CV_16SC2);
  for (auto _ : state) {
    cv::remap(f.input, f.output, m1, m2, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  }
}

BENCHMARK(BM_Mesh)->Apply(Args);
BENCHMARK(BM_Maps)->Apply(Args);
BENCHMARK(BM_Remap)->Apply(Args);
BENCHMARK(BM_DirectSample)->Apply(Args);
BENCHMARK(BM_DirectSamplePortable)->Apply(Args);
BENCHMARK(BM_WarpEndToEnd)->Apply(Args);
BENCHMARK(BM_BareRemapFloor)->Apply(Args);

}  // namespace
}  // namespace steadiface

BENCHMARK_MAIN();
