#pragma once
// What the nonlinear solve of the steady problem is asked to do, and what it reports.
#include <string>
#include <vector>

#include "solver/ns/flow_field.h"

namespace naris::nonlinear {

struct NonlinearOptions {
  int max_iterations = 50;
  double tolerance = 1e-8;  // on the residual 2-norm relative to that of the load (F with data)
  double absolute_tolerance = 1e-13;
  double relaxation = 1.0;  // U ← U + ω (U* − U), the largest ω (step_damping.h)
  // Newton's method (oseen_element.h: only the reconstructed viscous term stays lagged) after
  // this many Picard steps.
  bool newton = true;
  int picard_steps = 2;
  // Each linear solve (for the correction, from a zero guess) stops when its residual has
  // fallen by this factor: the nonlinear residual times this is what the step leaves unsolved.
  double linear_tolerance = 1e-3;
  // … at the tightest: the tolerance of each step follows how fast the nonlinear residual falls
  // (forcing_term.h), between linear_tolerance and this (equal: a fixed tolerance).
  double loosest_linear_tolerance = 0.1;
  // Pseudo-transient continuation: the first step's Courant number (0: off; pseudo_time.h).
  double pseudo_cfl = 0.0;
  // Give up (not converged) when the residual has not halved over this many steps (0: never):
  // a stalled attempt is better retried another way than run to max_iterations.
  int stall_steps = 0;
  // coupled: each step solves the whole linearized system (GMRES on ILU); segregated: one
  // sweep of FiDAP's segregated scheme (segregated_step.h) per Picard step, relaxed by
  // α_u and α_p — Picard only; segregated_krylov: GMRES on the whole system preconditioned by
  // that sweep (one AMG V-cycle per field, no relaxation).
  enum class Scheme { coupled, segregated, segregated_krylov };
  Scheme scheme = Scheme::coupled;
  double velocity_relaxation = 0.7, pressure_relaxation = 0.3;
  std::string options_prefix = "ns_";
  // Keep the linear solver's preconditioner from one nonlinear step to the next while that
  // pays (preconditioner_reuse.h); the converged answer is the same either way.
  bool reuse_preconditioner = true;
  bool log_iterations = false;  // a line per step (residual, relaxation, linear iterations)
  // Progress on long work: without log_iterations, a step's line once this many seconds have
  // passed since the solve began or since the last such line; and within a linear solve that
  // runs longer, a line this often. 0: none.
  double progress_seconds = 60.0;
};

// Pseudo-arclength continuation (Keller 1977): the Reynolds number joins the unknowns, and one
// equation more fixes how far along the branch's tangent (t_u, t_Re) the solution lies,
//   N(u, Re) = ⟨t_u, u − u₁⟩ + t_Re (Re − Re₁) / Re₁² − Δs = 0,
// with ⟨·,·⟩ the mean over the nodes of the velocities' dot product (pressure left out: it
// follows the velocity) and Re measured relative to Re₁. Where a branch of steady solutions
// turns back (a turning point, where the Jacobian is singular and no solution lies just beyond
// in Re) the iteration follows it around, which continuation in Re alone cannot. Newton's step
// on this bordered system: bordered_step.h.
struct ArclengthConstraint {
  ns::FlowField origin;   // u₁: the last point on the branch, on the piece (nondimensional)
  ns::FlowField tangent;  // t_u on the piece (its pressure is not used)
  double origin_reynolds = 0.0;   // Re₁
  double tangent_reynolds = 0.0;  // t_Re
  double step = 0.0;              // Δs
};

struct NonlinearReport {
  std::vector<double> residuals;  // nonlinear residual 2-norm before each solve, and the last
  int iterations = 0;
  int preconditioner_builds = 0;  // linear solves that set the preconditioner up anew
  int linear_iterations = 0;
  bool converged = false;
  double reynolds = 0.0;  // with an arclength constraint: the Re of the answer (else the given)
  // With an arclength constraint, when the last step was Newton's: the branch's unit tangent
  // at the answer, (du/dRe, 1) from that step's ∂R/∂Re solve, scaled to unit length in the
  // constraint's metric at the answer's Re and pointing the constraint's way (on the piece;
  // its pressure is dp/dRe alike). Empty otherwise.
  ns::FlowField tangent;
  double tangent_reynolds = 0.0;
};

}  // namespace naris::nonlinear
