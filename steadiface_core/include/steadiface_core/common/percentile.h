#pragma once

#include <vector>

namespace steadiface {

/// Nearest-rank percentile of `values` (p in [0, 1]; 0.5 = median); 0 for
/// an empty vector. Used by the scorecard, the tools and the benchmarks.
double Percentile(std::vector<double> values, double p);

}  // namespace steadiface
