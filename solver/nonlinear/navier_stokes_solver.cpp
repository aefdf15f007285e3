#include "solver/nonlinear/navier_stokes_solver.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/error.h"
#include "core/log.h"
#include "solver/nonlinear/bordered_step.h"
#include "solver/nonlinear/forcing_term.h"
#include "solver/nonlinear/linear_solver.h"
#include "solver/nonlinear/pseudo_time.h"
#include "solver/nonlinear/step_damping.h"
#include "solver/ns/distributed_field.h"
#include "solver/ns/oseen_system.h"
#include "solver/ns/segregated_step.h"

namespace naris::nonlinear {
namespace {

using ns::FlowField;
using petsc::check;
using Scheme = NonlinearOptions::Scheme;

MPI_Comm communicator_of(const ns::FlowProblem& problem) {
  return problem.communicator == MPI_COMM_NULL ? PETSC_COMM_WORLD : problem.communicator;
}

// One nonlinear solve: the iterate, the system it is linearized in, and the policies that
// steer the steps.
class NavierStokesSolver {
 public:
  NavierStokesSolver(const HybridMesh& mesh, const parallel::NodeNumbering& numbering,
                     const ns::FlowProblem& problem, const NonlinearOptions& options,
                     const FlowField* initial, const ArclengthConstraint* arclength)
      : options_(options),
        problem_(problem),
        comm_(communicator_of(problem)),
        n_(mesh.nodes.size()),
        reynolds_(problem.reynolds),
        nu_(1.0 / problem.reynolds),
        // The segregated sweep takes the velocity and pressure blocks out: scalar (AIJ) storage.
        system_(mesh, numbering, comm_, options.options_prefix, problem.backflow,
                options.scheme == Scheme::coupled ? MATBAIJ : MATAIJ),
        damping_(options.relaxation, !(options.pseudo_cfl > 0.0)),
        pseudo_time_(options.pseudo_cfl),
        stokes_(initial == nullptr) {
    field_ = initial ? *initial
                     : FlowField{std::vector<Eigen::Vector3d>(n_, Eigen::Vector3d::Zero()),
                                 std::vector<double>(n_, 0.0)};
    if (options.scheme == Scheme::segregated)
      sweep_.emplace(system_.matrix(), options.options_prefix, options.velocity_relaxation,
                     options.pressure_relaxation);
    if (options.scheme == Scheme::segregated_krylov)
      sweep_.emplace(system_.matrix(), options.options_prefix, 1.0, 1.0, true);
    fix_boundary_values();
    if (options.scheme == Scheme::coupled && options.newton) system_.use_newton_operator(rows_);
    linear_.emplace(comm_, options, sweep_ ? &*sweep_ : nullptr);
    eta_ = linear_->tightest_tolerance();
    check(VecDuplicate(system_.solution(), current_.out()), "VecDuplicate");
    check(VecDuplicate(system_.solution(), product_.out()), "VecDuplicate");
    if (arclength) {
      bordered_.emplace(*arclength, system_, numbering, comm_);
      picard_run_ = options.picard_steps;  // the predictor is close: Newton from the first step
    }
  }

  FlowField solve(NonlinearReport& r) {
    r = {};
    clock_ = Stopwatch();  // progress lines count from the first step
    for (int it = 0; solves_ <= options_.max_iterations + 1 && it < 4 * options_.max_iterations + 8;
         ++it) {
      const Next next = step(r);
      if (next == Next::stop) break;
    }
    r.reynolds = reynolds_;
    return std::move(field_);
  }

 private:
  enum class Next { go_on, stop };

  // The Dirichlet data into the iterate, and the rows of this rank they fix.
  void fix_boundary_values() {
    const ns::DirichletConditions& bc = problem_.conditions;
    for (std::size_t k = 0; k < bc.nodes.size(); ++k)
      field_.velocity[static_cast<std::size_t>(bc.nodes[k])] = bc.values[k];
    if (bc.pressure_pin)
      field_.pressure[static_cast<std::size_t>(bc.pressure_pin->first)] = bc.pressure_pin->second;
    rows_ = system_.fixed_rows(bc);
    zeros_.assign(rows_.size(), 0.0);
  }

  // One pass: linearize at the iterate, test convergence, damp or take the step.
  Next step(NonlinearReport& r) {
    system_.distribute(field_, current_);
    const bool newton = !stokes_ && options_.newton && options_.scheme != Scheme::segregated &&
                        picard_run_ >= options_.picard_steps;
    const auto linearization = stokes_  ? ns::Linearization::picard
                               : newton ? ns::Linearization::newton
                                        : ns::Linearization::picard_residual;
    if (bordered_) bordered_->sample_residual_above(field_, reynolds_, problem_.force);
    system_.assemble(
        stokes_ ? std::vector<Eigen::Vector3d>(n_, Eigen::Vector3d::Zero()) : field_.velocity,
        field_.pressure, nu_, problem_.force, linearization);
    bool pseudo_step = false;  // the matrix holds a pseudo-time term
    double norm = 0.0;
    if (!stokes_) {
      norm = residual_norm();
      if (bordered_) bordered_->differentiate(reynolds_, rows_);
      if (pseudo_time_.enabled() && norm > 0.0) {
        pseudo_step = PseudoTimeLaw::time_like(pseudo_time_.next(norm, previous_norm_));
        if (pseudo_step) system_.add_pseudo_time(field_.velocity, nu_, pseudo_time_.cfl());
      }
    }
    check(MatZeroRows(system_.matrix(), static_cast<PetscInt>(rows_.size()), rows_.data(), 1.0,
                      current_, system_.rhs()),
          "MatZeroRows");
    if (!stokes_) {
      if (converged(norm)) {
        r.residuals.push_back(norm);
        r.converged = true;
        if (bordered_) bordered_->report_tangent(field_, reynolds_, r);
        return Next::stop;
      }
      if (damping_.backtrack(norm, previous_norm_, !previous_.pressure.empty())) {
        if (newton_step_ && damping_.cut_short()) picard_run_ = 0;
        relax();
        return Next::go_on;
      }
      if (!std::isfinite(norm)) fail("the nonlinear iteration diverged (residual {})", norm);
      r.residuals.push_back(norm);
      damping_.accepted(norm, previous_norm_, newton_step_);
      eta_ = forcing_term(norm, previous_norm_, eta_, linear_->tightest_tolerance(),
                          options_.loosest_linear_tolerance);
      previous_norm_ = norm;
      if (solves_ > options_.max_iterations || stalled(r.residuals)) return Next::stop;
    }
    LinearSolve linear = solve_correction(newton, pseudo_step, r);
    const double reynolds_step =
        bordered_ && !stokes_
            ? bordered_->correct(*linear_, field_, reynolds_, eta_, newton, linear, r)
            : 0.0;
    check(VecAYPX(system_.solution(), 1.0, current_), "VecAYPX");
    ++solves_;
    log_step(newton, linear.description, reynolds_step);
    if (linear.reason < 0)
      fail("the linear solver failed ({})", KSPConvergedReasons[linear.reason]);
    take_step(newton, reynolds_step, r);
    return Next::go_on;
  }

  // The nonlinear residual K(u)u − F(u) at the current iterate; fixed rows hold exactly.
  double residual_norm() {
    check(VecSetValues(system_.residual(), static_cast<PetscInt>(rows_.size()), rows_.data(),
                       zeros_.data(), INSERT_VALUES),
          "VecSetValues");
    check(VecAssemblyBegin(system_.residual()), "VecAssemblyBegin");
    check(VecAssemblyEnd(system_.residual()), "VecAssemblyEnd");
    double norm = 0.0;
    check(VecNorm(system_.residual(), NORM_2, &norm), "VecNorm");
    return norm;
  }

  // Relative to the load (forces and boundary data): an iterate that starts close, as a warm
  // start does, must not be held to a fraction of its own small first residual. A damped step
  // leaves part of the (linear) arclength constraint unmet: one step more.
  bool converged(double norm) {
    double load = 0.0;
    check(VecNorm(system_.rhs(), NORM_2, &load), "VecNorm");
    const bool on_constraint = !bordered_ || bordered_->on_constraint(field_, reynolds_);
    return (norm <= options_.absolute_tolerance || norm <= options_.tolerance * load) &&
           on_constraint;
  }

  // Not halved over the last stall_steps steps: better retried another way.
  bool stalled(const std::vector<double>& history) const {
    const auto window = static_cast<std::size_t>(options_.stall_steps);
    return window > 0 && history.size() > window &&
           history.back() > 0.5 * history[history.size() - 1 - window];
  }

  // The correction δ = U* − U from a zero guess, so that the linear tolerance is relative to the
  // current nonlinear residual (an inexact Newton/Picard step): J δ = −R with Newton's J or
  // Picard's K(a) (R = K(u)U − F(u) for both). The pseudo-time term changes the matrix only.
  // The first Stokes solve corrects the boundary data: K δ = F − K U. Fixed rows have a zero
  // residual, so δ = 0 there.
  LinearSolve solve_correction(bool newton, bool pseudo_step, NonlinearReport& r) {
    if (!stokes_) {
      check(VecAXPBY(system_.rhs(), -1.0, 0.0, system_.residual()), "VecAXPBY");
    } else {
      check(MatMult(system_.matrix(), current_, product_), "MatMult");
      check(VecAXPY(system_.rhs(), -1.0, product_), "VecAXPY");
    }
    if (options_.scheme == Scheme::segregated) {
      sweep_->apply(system_.matrix(), system_.rhs(), system_.solution());
      LinearSolve out;
      out.description = fmt::format("{} momentum and {} pressure iterations",
                                    sweep_->momentum_iterations(), sweep_->pressure_iterations());
      return out;
    }
    const auto kind = stokes_  ? LinearProblem::stokes
                      : newton ? LinearProblem::newton
                               : LinearProblem::picard;
    // Newton's step on the coupled system solves with the whole derivative, preconditioned by
    // the assembled part — but not a pseudo-time step, where the whole derivative made the
    // transient diverge (docs/results/solver-choices.md).
    const bool exact = newton && !pseudo_step && options_.scheme == Scheme::coupled;
    const Mat op = exact ? system_.newton_operator(field_.velocity, nu_) : system_.matrix();
    return linear_->solve(kind, op, system_.matrix(), system_.rhs(), system_.solution(), eta_, r);
  }

  void log_step(bool newton, const std::string& linear, double reynolds_step) {
    const bool progress_due = options_.progress_seconds > 0.0 &&
                              clock_.seconds() - last_line_ >= options_.progress_seconds;
    if (progress_due) last_line_ = clock_.seconds();
    if (!(options_.log_iterations || progress_due) || system_.rank() != 0) return;
    log_line(fmt::format(
        "    {} {:3d}: {}, relaxation {:.3f}, CFL {:.3g}, {}{}", newton ? "Newton" : "Picard",
        solves_,
        // The Stokes start has no residual before it: its solve is the first iterate.
        stokes_ ? std::string("Stokes start") : fmt::format("residual {:.3e}", previous_norm_),
        stokes_ ? 1.0 : damping_.omega(), stokes_ ? INFINITY : pseudo_time_.cfl(), linear,
        bordered_ ? fmt::format(", Re {:.4f} → {:.4f}", reynolds_, reynolds_ + reynolds_step)
                  : ""));
  }

  // The solve's answer becomes the target of the damped step from the iterate.
  void take_step(bool newton, double reynolds_step, NonlinearReport& r) {
    if (stokes_) {
      system_.gather(system_.solution(), field_);
    } else {
      previous_ = field_;
      target_ = field_;
      system_.gather(system_.solution(), target_);
      previous_reynolds_ = reynolds_;
      target_reynolds_ = reynolds_ + reynolds_step;
      relax();
      ++r.iterations;
      if (!newton) ++picard_run_;
    }
    newton_step_ = newton;
    stokes_ = false;
  }

  // U ← U₀ + ω (U* − U₀); with an arclength constraint Re moves with the field, relaxed alike.
  void relax() {
    const double omega = damping_.omega();
    for (std::size_t k = 0; k < n_; ++k) {
      field_.velocity[k] =
          previous_.velocity[k] + omega * (target_.velocity[k] - previous_.velocity[k]);
      field_.pressure[k] =
          previous_.pressure[k] + omega * (target_.pressure[k] - previous_.pressure[k]);
    }
    if (bordered_) {
      reynolds_ = previous_reynolds_ + omega * (target_reynolds_ - previous_reynolds_);
      nu_ = 1.0 / reynolds_;
    }
  }

  const NonlinearOptions& options_;
  const ns::FlowProblem& problem_;
  MPI_Comm comm_;
  std::size_t n_;
  // The Re (and ν) of the iterate; with an arclength constraint also those of the step's start
  // and of the solve's answer.
  double reynolds_, nu_;
  double previous_reynolds_ = reynolds_, target_reynolds_ = reynolds_;
  ns::OseenSystem system_;
  std::optional<ns::SegregatedStep> sweep_;
  std::optional<LinearSolver> linear_;
  std::optional<BorderedStep> bordered_;
  StepDamping damping_;
  PseudoTimeLaw pseudo_time_;
  std::vector<PetscInt> rows_;  // fixed by Dirichlet conditions (global)
  std::vector<double> zeros_;
  petsc::Vector current_, product_;
  FlowField field_, previous_, target_;  // the iterate, a step's start, the solve's answer
  bool stokes_;                          // Stokes first (a = 0) unless warm-started
  bool newton_step_ = false;             // the kind of the last solve
  int solves_ = 0, picard_run_ = 0;
  double previous_norm_ = INFINITY, eta_ = 0.0;  // eta: the linear solve's tolerance
  Stopwatch clock_;
  double last_line_ = 0.0;  // when the last step's line was printed, s into the solve
};

}  // namespace

FlowField solve_navier_stokes(const HybridMesh& mesh, const parallel::NodeNumbering& numbering,
                              const ns::FlowProblem& problem, const NonlinearOptions& options,
                              NonlinearReport* report, const FlowField* initial,
                              const ArclengthConstraint* arclength) {
  if (!(problem.reynolds > 0.0) || !std::isfinite(problem.reynolds))
    fail("the Reynolds number must be positive and finite (got {})", problem.reynolds);
  if (arclength && (!initial || !options.newton || options.pseudo_cfl > 0.0 ||
                    options.scheme != Scheme::coupled))
    fail("internal: an arclength step needs a predicted field and coupled Newton steps");
  const ns::DirichletConditions& bc = problem.conditions;
  if (bc.nodes.size() != bc.values.size())
    fail("Dirichlet conditions: {} nodes but {} values", bc.nodes.size(), bc.values.size());
  NavierStokesSolver solver(mesh, numbering, problem, options, initial, arclength);
  NonlinearReport local;
  return solver.solve(report ? *report : local);
}

FlowField solve_navier_stokes(const HybridMesh& mesh, const ns::FlowProblem& problem,
                              const NonlinearOptions& options, NonlinearReport* report,
                              const FlowField* initial) {
  const MPI_Comm comm = communicator_of(problem);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  if (ranks == 1)
    return solve_navier_stokes(mesh, parallel::whole_numbering(mesh.nodes.size()), problem, options,
                               report, initial);
  const parallel::MeshPiece piece = parallel::mesh_piece(mesh, rank, ranks);
  std::optional<FlowField> start;
  if (initial) start = ns::local_field(*initial, piece.numbering);
  ns::FlowProblem local = problem;
  local.conditions = ns::local_conditions(problem.conditions, piece.numbering);
  const FlowField f = solve_navier_stokes(piece.mesh, piece.numbering, local, options, report,
                                          start ? &*start : nullptr);
  return ns::gather_field(f, piece.numbering, comm);
}

}  // namespace naris::nonlinear
