#pragma once
// How exactly each inexact Newton (or Picard) step solves its linear system.
#include <algorithm>
#include <cmath>

namespace naris::nonlinear {

// The relative tolerance of the next linear solve, by Eisenstat & Walker (1996), choice 2:
// η = γ (‖R_k‖ / ‖R_{k−1}‖)^α with γ = 0.9, α = 2, kept at least γ η_{k−1}^α when that exceeds
// 0.1 (one lucky drop of the residual must not ask for a tight solve at once), within
// [tightest, loosest]; the first step of a solve, with no ratio yet, gets `loosest`.
// Where the outer iteration contracts slowly — pseudo-time steps at a small Courant number,
// damped Newton steps far from the solution — a linear solve tighter than the residual will
// fall is wasted; near the solution, where Newton converges fast, η falls with the ratio and
// the steps stay Newton's. The solves take far fewer GMRES iterations than with a fixed
// tolerance (docs/results/solver-choices.md).
inline double forcing_term(double residual, double previous_residual, double previous_eta,
                           double tightest, double loosest) {
  constexpr double gamma = 0.9, alpha = 2.0;
  if (!(std::isfinite(previous_residual) && previous_residual > 0.0)) return loosest;
  double eta = gamma * std::pow(residual / previous_residual, alpha);
  const double safeguard = gamma * std::pow(previous_eta, alpha);
  if (safeguard > 0.1) eta = std::max(eta, safeguard);
  return std::clamp(eta, tightest, std::max(tightest, loosest));
}

}  // namespace naris::nonlinear
