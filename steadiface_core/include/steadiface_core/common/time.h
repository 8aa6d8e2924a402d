#pragma once

#include <chrono>
#include <cstdint>

namespace steadiface {

/// The core's clock: integer nanoseconds on whatever clock the sensors stamp
/// (the ROS layer converts ros::Time). Integers keep sub-microsecond precision
/// for epoch-sized stamps, which a double in seconds would not.
struct SensorClock {
  using rep = int64_t;
  using period = std::nano;
  using duration = std::chrono::duration<rep, period>;
  using time_point = std::chrono::time_point<SensorClock>;
  static constexpr bool is_steady = false;
};

using Duration = SensorClock::duration;
using Time = SensorClock::time_point;

/// Seconds (may be fractional or negative) to a Duration, rounded to the
/// nearest nanosecond.
Duration FromSeconds(double seconds);
/// A Duration in seconds.
double ToSeconds(Duration d);
/// Time since the clock's epoch in seconds (loses precision for large stamps:
/// use only for logging and plots).
double ToSeconds(Time t);
/// A Time from integer nanoseconds since the clock's epoch.
inline Time FromNanoseconds(int64_t ns) { return Time(Duration(ns)); }
/// Integer nanoseconds since the clock's epoch.
inline int64_t ToNanoseconds(Time t) { return t.time_since_epoch().count(); }

}  // namespace steadiface
