#pragma once
// The benchmarks' input: the first frames of the simulator's walking selfie
// at a size, rendered once per size and kept for the process. Without the
// preset or the simulator (no test data), no frames: the benchmark skips.
#include <memory>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace bench {

struct WalkFrames {
  std::unique_ptr<sim::Simulator> sim;
  std::vector<cv::Mat> frames;       ///< BGR, as rendered
  std::vector<sim::SimTruth> truth;  ///< each frame's truth
};

/// Up to `count` frames of `walk` at w x h (cached by size and count).
inline const WalkFrames& GetWalkFrames(int w, int h, int count) {
  static std::vector<std::pair<std::vector<int>, WalkFrames>> cache;
  const std::vector<int> key{w, h, count};
  for (auto& c : cache) {
    if (c.first == key) return c.second;
  }
  WalkFrames s;
  sim::SimulatorOptions o;
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  const bool preset = sim::ApplyPreset("walk", &o).ok();
  o.width = w;
  o.height = h;
  o.duration_s = (count + 1) / o.fps;
  if (preset && sim::Simulator::Create(o, &s.sim).ok()) {
    for (int i = 0; i < s.sim->num_frames() && i < count; ++i) {
      cv::Mat f;
      sim::SimTruth truth;
      if (!s.sim->Render(i, &f, &truth).ok()) break;
      s.frames.push_back(f);
      s.truth.push_back(truth);
    }
  }
  cache.emplace_back(key, std::move(s));
  return cache.back().second;
}

}  // namespace bench
}  // namespace steadiface
