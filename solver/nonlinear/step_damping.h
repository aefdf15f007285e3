#pragma once
// How much of each nonlinear step is taken: U ← U + ω (U* − U), a backtracking line search on
// the full residual.
#include <algorithm>

namespace naris::nonlinear {

// ω starts at the largest relaxation; when a step raises the residual, ω is halved and the step
// retaken from the previous iterate (no new solve), down to 1/64. After a step that halves the
// residual, three steps in a row that lower it, or a Newton step that lowers it (its full step
// is the one to try first), ω grows back towards the largest. Under pseudo-time every step is
// taken: a transient may have to raise the residual on its way, and the falling Courant number
// is the damping.
class StepDamping {
 public:
  StepDamping(double largest, bool backtracking)
      : largest_(largest), omega_(largest), backtracking_(backtracking) {}
  double omega() const { return omega_; }
  // Whether the step that led from residual `previous` to `norm` is to be retaken shorter (ω is
  // then halved); `retakeable`: there is an iterate to retake it from.
  bool backtrack(double norm, double previous, bool retakeable) {
    if (norm < previous || !retakeable || !(omega_ > 1.0 / 64) || !backtracking_) return false;
    omega_ *= 0.5;
    return true;
  }
  // A Newton step cut this short hands back to Picard, which contracts more robustly far from
  // the solution.
  bool cut_short() const { return omega_ < 0.125; }
  // The step that led from `previous` to `norm` is taken.
  void accepted(double norm, double previous, bool newton_step) {
    decreasing_ = norm < previous ? decreasing_ + 1 : 0;
    if (norm < 0.5 * previous || decreasing_ >= 3 || (newton_step && decreasing_ > 0)) {
      omega_ = std::min(largest_, 2.0 * omega_);
      decreasing_ = 0;
    }
  }

 private:
  double largest_, omega_;
  bool backtracking_;
  int decreasing_ = 0;
};

}  // namespace naris::nonlinear
