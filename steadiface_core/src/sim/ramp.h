#pragma once
// Time profiles of the simulator's events (private to src/sim/).

namespace steadiface {
namespace sim {

// 0 before a, 1 after b, smooth in between.
inline double Ramp(double t, double a, double b) {
  if (t <= a) return 0.0;
  if (t >= b) return 1.0;
  const double s = (t - a) / (b - a);
  return s * s * (3 - 2 * s);
}

inline bool Active(double t, double start, double end) {
  return start >= 0 && t >= start && (end < 0 || t < end);
}

}  // namespace sim
}  // namespace steadiface
