#include "solver/continuation/reynolds_continuation.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "solver/continuation/arclength.h"

namespace naris::continuation {

using nonlinear::ArclengthConstraint;
using nonlinear::NonlinearOptions;
using nonlinear::NonlinearReport;
using ns::FlowField;

ReynoldsContinuation::ReynoldsContinuation(const ContinuationSettings& settings,
                                           SteadySolves& solves)
    : settings_(settings), solves_(solves) {
  re_ = step_ = std::min(settings.start, settings.target);
}

void ReynoldsContinuation::resume(FlowField field, double reynolds, ContinuationState state) {
  last_good_ = std::move(field);
  reached_ = reynolds;
  if (state.next_step > 0.0) {
    // Where the interrupted run stood: the restart takes the path it would have taken.
    step_ = state.next_step;
    pseudo_first_ = state.pseudo_time;
    resume_arclength_ = state.arclength_step;
    earlier_re_ = state.earlier_reynolds;
    earlier_ = std::move(state.earlier);
  } else {
    // A file without the continuation (solution.h5): a quarter of the way so far, grown if
    // easy (a doubling of Re in one step is too much for the constricted jets of real
    // anatomy), Newton first.
    step_ = std::max(0.25 * reached_, 1.0);
    pseudo_first_ = false;
  }
  re_ = std::min(settings_.target, reached_ + step_);
  if (reached_ >= settings_.target) {
    // A prolonged field at the target: the target's step starts from it, Newton first.
    re_ = step_ = settings_.target;
    reached_ = 0.0;
  }
}

NonlinearOptions ReynoldsContinuation::attempt(bool pseudo, double re) const {
  const NonlinearOptions& base = settings_.nonlinear;
  NonlinearOptions o = base;
  if (re < settings_.target) o.tolerance = std::max(base.tolerance, settings_.step_tolerance);
  if (base.pseudo_cfl > 0.0 && !pseudo) {
    o.pseudo_cfl = 0.0;
    o.max_iterations = std::min(base.max_iterations, 25);
    // Where Newton fails it crawls: five steps without halving the residual hand over to
    // pseudo-time.
    o.stall_steps = 5;
  }
  return o;
}

// Newton alone on a short budget, to the steps' tolerance: the points of the branch.
NonlinearOptions ReynoldsContinuation::newton_only() const {
  const NonlinearOptions& base = settings_.nonlinear;
  NonlinearOptions o = base;
  o.pseudo_cfl = 0.0;
  o.max_iterations = std::min(base.max_iterations, 25);
  o.stall_steps = 5;
  o.tolerance = std::max(base.tolerance, settings_.step_tolerance);
  return o;
}

// One solve at `re` (with `constraint`: its predictor's), its counts into `cs`, which joins
// the history (and the whole report into `kept`, if given). A diverged iteration is a failed
// try; the field is then empty.
FlowField ReynoldsContinuation::solve_step(ContinuationStep& cs, double re,
                                           const NonlinearOptions& o, const FlowField* initial,
                                           const ArclengthConstraint* constraint,
                                           NonlinearReport* kept) {
  Stopwatch clock;
  NonlinearReport report;
  FlowField f;
  try {
    f = solves_.solve(re, o, initial, constraint, report);
    cs.converged = report.converged && (!constraint || report.reynolds > 0.0);
    if (constraint) cs.reynolds = report.reynolds;
  } catch (const Error& e) {
    cs.converged = false;
    log_line(fmt::format("  Re {:.1f}: {}", re, e.what()));
  }
  cs.iterations = report.iterations;
  cs.linear_iterations = report.linear_iterations;
  cs.preconditioner_builds = report.preconditioner_builds;
  cs.residuals = report.residuals;
  cs.residual = report.residuals.empty() ? NAN : report.residuals.back();
  cs.seconds = clock.seconds();
  steps_.push_back(cs);
  if (kept) *kept = std::move(report);
  return f;
}

// With pseudo-time available, each Re is tried with both methods before the increment is
// halved: Newton alone (on a short budget) and with pseudo-time, first the one that took the
// last step. Newton from the last solution follows the steady branch even where that branch
// is unstable, which time-like steps cannot; where Newton fails, pseudo-time carries the flow
// across. From rest pseudo-time goes first: the Stokes field is far from the first step's
// solution, where damped Newton steps crawl (docs/method/continuation.md).
void ReynoldsContinuation::run() {
  bool retry = false;  // the second try at this Re, with the other method
  if (resume_arclength_ > 0.0) follow_branch(resume_arclength_);
  for (int s = 0; s < settings_.max_steps && reached_ < settings_.target; ++s) try_step(retry);
  if (reached_ < settings_.target)
    give_up(fmt::format(
        "the continuation reached Re {:.1f} of {:.1f} in {} steps; {} holds that step (resume "
        "with --restart)",
        reached_, settings_.target, settings_.max_steps, settings_.checkpoint));
}

void ReynoldsContinuation::try_step(bool& retry) {
  const bool pseudo_available = settings_.nonlinear.pseudo_cfl > 0.0;
  ContinuationStep cs;
  cs.reynolds = re_;
  const bool pseudo = pseudo_available && (pseudo_first_ != retry);
  const NonlinearOptions o = attempt(pseudo, re_);
  // The first try at each Re starts from the secant predictor through the last two converged
  // fields, u(Re) ≈ u₁ + (u₁ − u₀)(Re − Re₁)/(Re₁ − Re₀) (the boundary data are the same, so it
  // keeps them). A retry starts from the last converged field itself, as does every step after
  // one that needed pseudo-time (no secant then: `earlier_re_` is 0).
  const bool predict = earlier_re_ > 0.0 && !retry;
  FlowField predicted;
  if (predict) {
    const double t = (1.0 / re_ - 1.0 / reached_) / (1.0 / reached_ - 1.0 / earlier_re_);
    predicted = blend(earlier_, last_good_, 1.0 + t);
  }
  FlowField field = solve_step(cs, re_, o,
                               predict                        ? &predicted
                               : !last_good_.pressure.empty() ? &last_good_
                                                              : nullptr,
                               nullptr);
  log_line(fmt::format("  Re {:8.1f}: {} after {} nonlinear steps{}, residual {:.2e}, {:.1f} s",
                       re_, cs.converged ? "converged" : "FAILED", cs.iterations,
                       pseudo ? " with pseudo-time" : "", cs.residual, cs.seconds));
  if (cs.converged) {
    accept(std::move(field), cs.iterations, o.max_iterations, pseudo);
    retry = false;
  } else if (pseudo_available && !retry) {
    retry = true;  // the same Re again, with the other method
  } else {
    retry = false;
    reject();
  }
}

// A converged step: the increment grows after an easy one, and the step goes to disk with
// what comes next.
void ReynoldsContinuation::accept(FlowField field, int iterations, int max_iterations,
                                  bool pseudo) {
  // A step that needed pseudo-time may have crossed to another branch: no secant through the
  // two branches.
  earlier_re_ = 0.0;
  if (reached_ > 0.0 && !pseudo) {
    earlier_ = std::move(last_good_);
    earlier_re_ = reached_;
  }
  last_good_ = std::move(field);
  reached_ = re_;
  if (iterations < max_iterations / 3) step_ *= 1.5;
  re_ = std::min(settings_.target, re_ + step_);
  pseudo_first_ = pseudo;
  ContinuationState state;
  state.next_step = step_;
  state.pseudo_time = pseudo;
  state.earlier_reynolds = earlier_re_;
  if (earlier_re_ > 0.0) state.earlier = earlier_;
  solves_.checkpoint(reached_, last_good_, state);
}

// Both methods failed: half the increment; a stall after Newton steps on one branch hands
// over to following the branch.
void ReynoldsContinuation::reject() {
  if (reached_ == 0.0) {
    step_ = re_ *= 0.5;  // the very first step: start lower
  } else {
    step_ = 0.5 * (re_ - reached_);  // half the increment that failed
    re_ = reached_ + step_;
  }
  if (step_ >= 1e-3 * settings_.target) return;
  const NonlinearOptions& base = settings_.nonlinear;
  const bool bordered = base.newton && base.scheme == NonlinearOptions::Scheme::coupled;
  if (settings_.arclength_steps > 0 && bordered) {
    // After pseudo-time steps there is one point only: the second of the secant by a Newton
    // step back from it, which stays on its branch.
    if (!(earlier_re_ > 0.0)) point_below();
    if (earlier_re_ > 0.0 && follow_branch(0.0)) return;
  }
  give_up(fmt::format(
      "the continuation stalled at Re {:.1f} (target {:.1f}): the step fell below {:.2f}{}",
      reached_, settings_.target, 1e-3 * settings_.target,
      reached_ > 0.0 ? "; " + settings_.checkpoint + " holds the last converged step" : ""));
}

void ReynoldsContinuation::point_below() {
  const double re_below = 0.99 * reached_;
  ContinuationStep cs;
  cs.reynolds = re_below;
  FlowField below = solve_step(cs, re_below, newton_only(), &last_good_, nullptr);
  log_line(fmt::format(
      "  Re {:8.2f}: {} after {} Newton steps (a second point of the branch, for its tangent), "
      "residual {:.2e}, {:.1f} s",
      re_below, cs.converged ? "converged" : "FAILED", cs.iterations, cs.residual, cs.seconds));
  if (!cs.converged) return;
  earlier_ = std::move(below);
  earlier_re_ = re_below;
}

void ReynoldsContinuation::record_branch_point(double re, const FlowField& field, int newton,
                                               double along) {
  ++branch_points_;
  solves_.branch_point(re, field, newton, along);
}

// Pseudo-arclength continuation along the branch through (earlier_, earlier_re_) and
// (last_good_, reached_), starting with arclength increment `ds` (0: the distance between the
// two). Returns true when the branch crossed the target and the target itself converged
// (last_good_ and reached_ then hold it); otherwise gives up, naming what the branch did.
bool ReynoldsContinuation::follow_branch(double ds) {
  log_line(fmt::format("  following the branch through Re {:.2f} and {:.2f} by arclength",
                       earlier_re_, reached_));
  const double re_first = reached_;
  // The first step goes along the secant through the last two points (unit in the
  // constraint's metric); later ones along the tangent each solve reports.
  ArclengthConstraint c;
  const InnerProduct inner = [this](const FlowField& a, const FlowField& b) {
    return solves_.inner_product(a, b);
  };
  const double secant = aim_along_secant(c, earlier_, earlier_re_, last_good_, reached_, inner);
  if (!(ds > 0.0)) ds = secant;
  const double smallest = ds / 64.0;
  double along = 0.0, lowest = reached_, highest = reached_;
  std::vector<double> turns;
  if (branch_points_ == 0) {
    record_branch_point(earlier_re_, earlier_, 0, -secant);
    record_branch_point(reached_, last_good_, 0, 0.0);
  }
  const NonlinearOptions o = newton_only();
  for (int k = 0; k < settings_.arclength_steps && ds >= smallest; ++k) {
    c.origin = last_good_;
    c.origin_reynolds = reached_;
    c.step = ds;
    const FlowField guess = arclength_predictor(c);
    ContinuationStep cs;
    cs.arclength = true;
    cs.reynolds = reached_ + ds * c.tangent_reynolds;
    NonlinearReport report;
    FlowField found = solve_step(cs, cs.reynolds, o, &guess, &c, &report);
    log_line(fmt::format(
        "  Re {:8.2f}: {} after {} Newton steps on the branch (arclength {:.3g}), residual "
        "{:.2e}, {:.1f} s",
        cs.reynolds, cs.converged ? "converged" : "FAILED", cs.iterations, ds, cs.residual,
        cs.seconds));
    if (!cs.converged) {
      ds *= 0.5;
      continue;
    }
    along += ds;
    if (cs.reynolds >= settings_.target) {
      if (converge_at_target(found, cs.reynolds, ds, along, o)) return true;
      ds *= 0.5;  // closer to the target next time
      continue;
    }
    // The branch turns where Re, along it, stops growing (or falling): where the tangent at
    // the new point (the secant only if the solve gave none) points back in Re.
    const double previous_direction = c.tangent_reynolds;
    earlier_ = std::move(last_good_);
    earlier_re_ = reached_;
    last_good_ = std::move(found);
    reached_ = cs.reynolds;
    if (!report.tangent.pressure.empty()) {
      c.tangent = std::move(report.tangent);
      c.tangent_reynolds = report.tangent_reynolds;
    } else {
      aim_along_secant(c, earlier_, earlier_re_, last_good_, reached_, inner);
    }
    if (previous_direction * c.tangent_reynolds < 0.0) {
      const double turn = previous_direction > 0.0 ? std::max(earlier_re_, reached_)
                                                   : std::min(earlier_re_, reached_);
      turns.push_back(turn);
      log_line(fmt::format("  the branch turns back near Re {:.2f} (a turning point)", turn));
    }
    lowest = std::min(lowest, reached_);
    highest = std::max(highest, reached_);
    record_branch_point(reached_, last_good_, cs.iterations, along);
    if (cs.iterations < o.max_iterations / 3) ds *= 1.5;
    ContinuationState state;
    state.next_step = ds;
    state.arclength_step = ds;
    state.earlier_reynolds = earlier_re_;
    state.earlier = earlier_;
    solves_.checkpoint(reached_, last_good_, state);
  }
  const std::string turned =
      turns.empty() ? std::string("no turning point found")
                    : fmt::format("it turns back at Re {:.2f}", fmt::join(turns, ", "));
  give_up(fmt::format(
      "the continuation stalled at Re {:.1f} (target {:.1f}); following the steady branch from "
      "there by arclength, {}, and it stayed between Re {:.1f} and {:.1f} ({} holds it, {} its "
      "last point)",
      re_first, settings_.target, turned, lowest, highest, settings_.branch, settings_.checkpoint));
}

// Past the target: the target itself, from the chord between the last point and `found`.
bool ReynoldsContinuation::converge_at_target(const FlowField& found, double re_found, double ds,
                                              double along, const NonlinearOptions& o) {
  const double target = settings_.target;
  const double t = (target - reached_) / (re_found - reached_);
  const FlowField start = blend(last_good_, found, t);
  ContinuationStep last;
  last.reynolds = target;
  NonlinearOptions exact = o;
  exact.tolerance = settings_.nonlinear.tolerance;
  FlowField at_target = solve_step(last, target, exact, &start, nullptr);
  log_line(fmt::format("  Re {:8.1f}: {} after {} Newton steps, residual {:.2e}, {:.1f} s", target,
                       last.converged ? "converged" : "FAILED", last.iterations, last.residual,
                       last.seconds));
  if (!last.converged) return false;
  earlier_ = std::move(last_good_);
  earlier_re_ = reached_;
  last_good_ = std::move(at_target);
  reached_ = target;
  record_branch_point(reached_, last_good_, last.iterations, along - (1.0 - t) * ds);
  return true;
}

[[noreturn]] void ReynoldsContinuation::give_up(const std::string& message) {
  solves_.giving_up(steps_);
  fail("{}", message);
}

}  // namespace naris::continuation
