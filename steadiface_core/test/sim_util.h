#pragma once
// A simulator for a preset, as the scenario tests build it.

#include <functional>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace testing_util {

/// The preset's simulator over test/data (3 s, 640x360 unless `tweak`
/// changes them); a failure is a test failure and a null result.
inline std::unique_ptr<sim::Simulator> MakeSimulator(
    const std::string& preset, const std::function<void(sim::SimulatorOptions*)>& tweak = {}) {
  sim::SimulatorOptions o;
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  EXPECT_TRUE(sim::ApplyPreset(preset, &o).ok());
  if (tweak) tweak(&o);
  std::unique_ptr<sim::Simulator> s;
  const Status st = sim::Simulator::Create(o, &s);
  EXPECT_TRUE(st.ok()) << st.message();
  return s;
}

}  // namespace testing_util
}  // namespace steadiface
