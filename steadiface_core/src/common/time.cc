#include "steadiface_core/common/time.h"

#include <cmath>

namespace steadiface {

Duration FromSeconds(double seconds) {
  return Duration(static_cast<int64_t>(std::llround(seconds * 1e9)));
}

double ToSeconds(Duration d) { return static_cast<double>(d.count()) * 1e-9; }

double ToSeconds(Time t) { return ToSeconds(t.time_since_epoch()); }

}  // namespace steadiface
