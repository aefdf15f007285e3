#pragma once
// When the nonlinear solver keeps the linear solver's preconditioner for the next step.
#include <algorithm>
#include <cmath>

namespace naris::nonlinear {

// Whether the next linear solve may keep the preconditioner built for an earlier one. Building
// ILU(1) is a large share of a solve's work (docs/results/solver-choices.md), and consecutive
// Picard or Newton matrices differ little near the solution; but a kept factorization costs
// iterations as the matrix drifts away from it. It is rebuilt for a new kind of linearization, and
// once the iterations the last solve added over the first one after the build cost more than a
// build; after a kept solve has run out of its budget, it is no longer kept at all (for the rest of
// that nonlinear solve). Costs are in any one unit (the solver passes floating-point operations).
// Solves to different tolerances (forcing_term.h) are compared by their iterations per decade of
// residual reduction.
enum class LinearProblem { stokes, picard, newton };

class PreconditionerReuse {
 public:
  explicit PreconditionerReuse(bool enabled) : enabled_(enabled) {}
  bool keeps(LinearProblem kind) const { return enabled_ && built_ && kind == kind_ && !stale_; }
  // `decades`: the reduction the solve was asked for, log10(1/tolerance).
  void built(LinearProblem kind, double setup_cost, double solve_cost, int iterations,
             double decades) {
    built_ = true;
    stale_ = false;
    kind_ = kind;
    setup_cost_ = setup_cost;
    fresh_rate_ = iterations / counted(decades);
    cost_per_iteration_ = solve_cost / std::max(iterations, 1);
  }
  void kept(double solve_cost, int iterations, double decades) {
    if (iterations > 0) cost_per_iteration_ = solve_cost / iterations;
    stale_ = (iterations - fresh_iterations(decades)) * cost_per_iteration_ > setup_cost_;
  }
  // A kept solve ran out of its budget (or failed): the matrices change too fast for keeping
  // to pay — each such solve wastes a whole solve to save a build
  // (docs/results/solver-choices.md) — so every later solve builds its own.
  void abandoned() { enabled_ = false; }
  // Iterations a solve with the kept preconditioner may take before it stops and is redone
  // with a fresh one: the iterations of a fresh solve plus a build's worth, so a kept
  // factorization that went bad costs at most twice what rebuilding at once would have
  // (docs/results/solver-choices.md).
  int iteration_budget(double decades) const {
    const double extra = setup_cost_ / std::max(cost_per_iteration_, 1e-12);
    return static_cast<int>(std::ceil(fresh_iterations(decades)) + std::min(extra, 1e6)) + 1;
  }

 private:
  bool enabled_ = false, built_ = false, stale_ = false;
  LinearProblem kind_ = LinearProblem::stokes;
  // What a fresh preconditioner would take for this reduction.
  double fresh_iterations(double decades) const { return fresh_rate_ * counted(decades); }
  // A solve asked for (almost) no reduction still counts as a tenth of a decade.
  static double counted(double decades) { return std::max(decades, 0.1); }

  double setup_cost_ = 0.0, cost_per_iteration_ = 0.0;
  double fresh_rate_ = 0.0;  // iterations per decade with a fresh preconditioner
};

}  // namespace naris::nonlinear
