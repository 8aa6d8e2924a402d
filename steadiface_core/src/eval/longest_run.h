#pragma once

#include <cstddef>
#include <utility>

namespace steadiface {
namespace eval {

// The longest run [first, second) of consecutive indices in [0, n) where
// `ok(i)` holds; the first such run on ties, empty if there is none.
template <typename Pred>
std::pair<size_t, size_t> LongestRun(size_t n, Pred ok) {
  std::pair<size_t, size_t> best(0, 0);
  for (size_t i = 0, start = 0; i <= n; ++i) {
    if (i < n && ok(i)) continue;
    if (i - start > best.second - best.first) best = {start, i};
    start = i + 1;
  }
  return best;
}

}  // namespace eval
}  // namespace steadiface
