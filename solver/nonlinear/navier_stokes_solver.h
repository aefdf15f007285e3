#pragma once
// The nonlinear solve of the steady Navier–Stokes problem on a hybrid mesh: a Stokes start (or
// a warm start), Picard steps on the stabilized Oseen problem, then Newton's method, each a
// damped step with backtracking (step_damping.h), optionally pseudo-transient
// (pseudo_time.h), each linear solve inexact (forcing_term.h) with a kept or rebuilt
// preconditioner (linear_solver.h); convergence judged on the full nonlinear residual. With an
// arclength constraint, Newton's steps are bordered (bordered_step.h).
#include "mesh/hybrid_mesh.h"
#include "solver/nonlinear/options.h"
#include "solver/ns/flow_problem.h"
#include "solver/parallel/partition.h"

namespace naris::nonlinear {

// Each rank of the problem's communicator passes its piece of the mesh (parallel::mesh_piece;
// the whole mesh with parallel::whole_numbering on one rank), the conditions and the initial
// field on that piece, and gets the field on it back. `initial` (optional) warm-starts;
// otherwise the first iterate is the Stokes solution.
// With `arclength` the Reynolds number is an unknown too (Newton steps only, no pseudo-time):
// problem.reynolds is the predictor's, `initial` the predicted field, and report->reynolds the
// Re found.
ns::FlowField solve_navier_stokes(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                                  const ns::FlowProblem& problem, const NonlinearOptions& options,
                                  NonlinearReport* report = nullptr,
                                  const ns::FlowField* initial = nullptr,
                                  const ArclengthConstraint* arclength = nullptr);

// The same from the whole mesh on every rank: the ranks cut it into pieces, solve, and each
// gets the whole field back. For tests and small problems.
ns::FlowField solve_navier_stokes(const HybridMesh& mesh, const ns::FlowProblem& problem,
                                  const NonlinearOptions& options,
                                  NonlinearReport* report = nullptr,
                                  const ns::FlowField* initial = nullptr);

}  // namespace naris::nonlinear
