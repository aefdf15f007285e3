#pragma once
// The Courant number of pseudo-transient continuation (Kelley & Keyes 1998) from step to step.
#include <algorithm>
#include <cmath>

namespace naris::nonlinear {

// Switched evolution relaxation: the Courant number follows the residual's fall, so the steps
// turn into Newton's (or Picard's) as the iteration converges — as the square of the ratio, but
// at most 4× a step (one residual that dips must not raise it tenfold), and never below a tenth
// of the first. Measurements behind the law: docs/results/solver-choices.md.
class PseudoTimeLaw {
 public:
  explicit PseudoTimeLaw(double first_cfl) : first_(first_cfl) {}
  bool enabled() const { return first_ > 0.0; }
  // The Courant number of the step taken at residual `norm`, the last one `previous` (∞ before
  // the first step).
  double next(double norm, double previous) {
    const double fall = previous / norm;
    cfl_ = std::isfinite(previous)
               ? std::clamp(cfl_ * fall * fall, 0.1 * first_, std::min(4.0 * cfl_, 1e12))
               : first_;
    return cfl_;
  }
  double cfl() const { return cfl_; }  // ∞ until the first step
  // Beyond this the term no longer changes the matrix in double precision: a plain step.
  static bool time_like(double cfl) { return cfl < 1e8; }

 private:
  double first_, cfl_ = INFINITY;
};

}  // namespace naris::nonlinear
