// libFuzzer: gyro ingestion. Random stamps (steps forward, backward, equal,
// huge), angular velocities (NaN, Inf, huge) and options; every accepted
// query must be finite and the buffer bounded.
#include <cstdlib>

#include "fuzz_util.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/gyro/row_rotations.h"

using namespace steadiface;  // NOLINT (test harness)

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  OrientationTimelineOptions o;
  o.buffer_duration_s = 0.5 + (in.Byte() % 20);
  o.max_samples = 16 + in.Get<uint16_t>() % 5000;
  o.max_extrapolation_s = (in.Byte() % 10) * 0.01;
  o.imu_time_offset_s = (static_cast<int>(in.Byte()) - 128) * 0.001;
  if (!ValidateOrientationTimelineOptions(o).ok()) return 0;
  OrientationTimeline tl(o);
  int64_t t = 1000000000;
  while (!in.done()) {
    const uint8_t op = in.Byte();
    if (op % 8 != 0) {
      const int64_t dt = static_cast<int64_t>(in.Get<int16_t>()) * 1000;  // +-32 ms
      t += dt;
      const Eigen::Vector3d w(in.Double(-10, 10), in.Double(-10, 10), in.Double(-10, 10));
      tl.AddSample({FromNanoseconds(t), w});
    } else if (!tl.empty()) {
      const Time q = FromNanoseconds(t + static_cast<int64_t>(in.Get<int16_t>()) * 100000);
      Eigen::Quaterniond R;
      if (QuerySucceeded(tl.RealRotation(q, &R))) {
        if (!R.coeffs().allFinite() || std::abs(R.norm() - 1.0) > 1e-6) abort();
      }
      double mean;
      if (tl.MeanAngularSpeed(q - FromSeconds(0.3), q, &mean) && !std::isfinite(mean)) abort();
      RollingShutterOptions rs;
      rs.readout_time_s = (in.Byte() % 40) * 0.001;
      RowRotations rows;
      if (QuerySucceeded(RowRotations::Build(tl, RowTiming(rs, 480), q, 8, &rows))) {
        if (!rows.At(in.Double(-100, 600)).coeffs().allFinite()) abort();
      }
    }
    if (tl.size() > static_cast<size_t>(o.max_samples)) abort();
  }
  return 0;
}
