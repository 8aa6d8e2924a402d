#include "steadiface_core/common/percentile.h"

#include <algorithm>

namespace steadiface {

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  const double q = std::min(std::max(p, 0.0), 1.0);
  const size_t k =
      std::min(values.size() - 1, static_cast<size_t>(q * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

}  // namespace steadiface
