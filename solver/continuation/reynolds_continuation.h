#pragma once
// Reynolds-number continuation (dissertation 4.2.5): from a low Re to the target in few large
// steps, each warm-started from the last converged one and checkpointed; and where it stalls at
// a turning point, the steady branch followed by pseudo-arclength continuation. The policy
// knows nothing of PETSc or MPI: it asks a SteadySolves for each solve.
#include <string>
#include <vector>

#include "solver/nonlinear/options.h"

namespace naris::continuation {

// One solve of the continuation, converged or not: the history that summary.json and
// residuals.csv report.
struct ContinuationStep {
  double reynolds = 0.0;  // of an arclength step: the Re it converged at (or was predicted)
  bool converged = false;
  bool arclength = false;  // a point of the branch followed past a stall
  int iterations = 0;
  int linear_iterations = 0, preconditioner_builds = 0;
  double residual = 0.0, seconds = 0.0;
  std::vector<double> residuals;
};

// Where the continuation stood after a converged step: what it does next. The earlier step
// feeds the secant predictor of the next one.
struct ContinuationState {
  double next_step = 0.0;         // 0: not known (a solution file, or an older checkpoint)
  bool pseudo_time = false;       // the step converged with pseudo-time
  double earlier_reynolds = 0.0;  // 0: no earlier step for the predictor
  ns::FlowField earlier;          // nondimensional, at earlier_reynolds
  double arclength_step = 0.0;    // > 0: following the branch by arclength
};

struct ContinuationSettings {
  double target = 610.0;  // the Reynolds number to reach
  double start = 50.0;    // the first step
  int max_steps = 40;     // continuation steps, failed ones included
  // The nonlinear tolerance of the steps before the target (relative to the load, like
  // nonlinear.tolerance, which holds at the target): they only start the next one. Looser is
  // not safely cheaper (docs/results/solver-choices.md).
  double step_tolerance = 1e-5;
  // Points of the branch followed by arclength where the continuation in Re stalls (0: fail
  // there).
  int arclength_steps = 30;
  nonlinear::NonlinearOptions nonlinear;  // per step
  // Where the checkpoint and the branch's points go, for the messages that name them.
  std::string checkpoint = "checkpoint.h5", branch = "branch.csv";
};

// What the continuation asks of the discrete problem. Every call may be collective.
class SteadySolves {
 public:
  virtual ~SteadySolves() = default;
  // The steady solution at `reynolds` from `initial` (null: from rest); with `constraint`, the
  // point of the branch on its hyperplane. May throw naris::Error (a failed try).
  virtual ns::FlowField solve(double reynolds, const nonlinear::NonlinearOptions& options,
                              const ns::FlowField* initial,
                              const nonlinear::ArclengthConstraint* constraint,
                              nonlinear::NonlinearReport& report) = 0;
  // ⟨a, b⟩ of the arclength constraint.
  virtual double inner_product(const ns::FlowField& a, const ns::FlowField& b) = 0;
  // The last converged step and where the continuation goes next, to resume from.
  virtual void checkpoint(double reynolds, const ns::FlowField& field,
                          const ContinuationState& state) = 0;
  // A point of the branch followed by arclength (the diagram that is the evidence).
  virtual void branch_point(double reynolds, const ns::FlowField& field, int newton_steps,
                            double arclength) = 0;
  // The history so far, just before the continuation gives up.
  virtual void giving_up(const std::vector<ContinuationStep>& steps) = 0;
};

class ReynoldsContinuation {
 public:
  ReynoldsContinuation(const ContinuationSettings& settings, SteadySolves& solves);
  // Start from a converged field at `reynolds` (a checkpoint) instead of from rest; a field at
  // the target itself (one prolonged from a coarser mesh) starts the target's step.
  void resume(ns::FlowField field, double reynolds, ContinuationState state);
  double next_reynolds() const { return re_; }
  // To the target; throws naris::Error, naming the last Re reached, when it cannot get there.
  void run();
  const ns::FlowField& solution() const { return last_good_; }
  const std::vector<ContinuationStep>& steps() const { return steps_; }

 private:
  // The options of a try at Re (below the target: the steps' tolerance), with pseudo-time or by
  // Newton alone on a short budget.
  nonlinear::NonlinearOptions attempt(bool pseudo, double re) const;
  nonlinear::NonlinearOptions newton_only() const;
  ns::FlowField solve_step(ContinuationStep& cs, double re, const nonlinear::NonlinearOptions& o,
                           const ns::FlowField* initial,
                           const nonlinear::ArclengthConstraint* constraint,
                           nonlinear::NonlinearReport* kept = nullptr);
  // One try at re_; `retry`: it is the second at this Re, with the other method (set for the
  // next try).
  void try_step(bool& retry);
  void accept(ns::FlowField field, int iterations, int max_iterations, bool pseudo);
  void reject();
  void point_below();
  bool follow_branch(double ds);
  void record_branch_point(double re, const ns::FlowField& field, int newton, double along);
  bool converge_at_target(const ns::FlowField& found, double re_found, double ds, double along,
                          const nonlinear::NonlinearOptions& options);
  [[noreturn]] void give_up(const std::string& message);

  ContinuationSettings settings_;
  SteadySolves& solves_;
  std::vector<ContinuationStep> steps_;
  // `reached` is the last converged Re (0: none yet), `last_good_` its field; `earlier_` the
  // converged field before it, at Re `earlier_re_` (0: none); re_ the next try, step_ the
  // increment.
  ns::FlowField last_good_, earlier_;
  double earlier_re_ = 0.0, re_ = 0.0, step_ = 0.0, reached_ = 0.0;
  bool pseudo_first_ = true;       // the method the last converged step needed goes first
  double resume_arclength_ = 0.0;  // > 0: the checkpoint was on a branch followed by arclength
  int branch_points_ = 0;
};

}  // namespace naris::continuation
