#pragma once
// Checks on a nonlinear solve's residual history, shared by the serial and MPI tests.
#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

namespace naris::testing {

// Whether the history ends as Newton's method with its whole derivative does: among the steps
// above round-off (1e-11 of the first residual), the last ratio of successive residuals is below
// a tenth of the one before. With a lagged term the ratios stall near a constant instead.
inline ::testing::AssertionResult ends_quadratically(const std::vector<double>& h) {
  std::size_t last = 0;
  while (last + 1 < h.size() && h[last + 1] > 1e-11 * h.front()) ++last;
  if (last < 3)
    return ::testing::AssertionFailure()
           << "only " << last + 1 << " residuals above round-off: too few to tell";
  const double before = h[last - 1] / h[last - 2], ratio = h[last] / h[last - 1];
  if (ratio < 0.1 * before) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "residuals " << h[last - 2] << ", " << h[last - 1] << ", " << h[last];
}

}  // namespace naris::testing
