#pragma once

#include <chrono>

namespace steadiface {

/// Wall time since `start` on the steady clock [ms]: the stage timings in
/// the frames' reports.
inline double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace steadiface
