#pragma once
// The Krylov solve of each nonlinear step's linear system, and whether it keeps the
// preconditioner of an earlier step (preconditioner_reuse.h).
#include <petscksp.h>

#include <string>

#include "core/log.h"
#include "solver/nonlinear/options.h"
#include "solver/nonlinear/preconditioner_reuse.h"
#include "solver/parallel/petsc.h"

namespace naris::ns {
class SegregatedStep;
}

namespace naris::nonlinear {

// What one linear solve did.
struct LinearSolve {
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  int iterations = 0;
  std::string description;  // for the step's log line
};

class LinearSolver {
 public:
  // GMRES (prefix options.options_prefix, SetFromOptions) on ILU(1) in RCM order on one rank,
  // additive Schwarz with ILU(1) blocks on several, or preconditioned by `sweep` (the
  // segregated_krylov scheme).
  LinearSolver(MPI_Comm comm, const NonlinearOptions& options, ns::SegregatedStep* sweep);
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  double tightest_tolerance() const { return tightest_; }
  // J δ = b to the relative tolerance eta, with `op` the operator and `matrix` what the
  // preconditioner is built from; a kept preconditioner that fails or runs over its budget is
  // rebuilt and the solve retaken.
  LinearSolve solve(LinearProblem kind, Mat op, Mat matrix, Vec b, Vec delta, double eta,
                    NonlinearReport& report);
  // A second right-hand side with the same operator and preconditioner (the bordered step).
  LinearSolve solve_again(Vec b, Vec x, double eta);

 private:
  // A line now and then from a long linear solve, which otherwise runs silent for minutes.
  struct Progress {
    Stopwatch clock;
    double interval = 0.0, last = 0.0, start_norm = 0.0;
  };
  static PetscErrorCode monitor(KSP solver, PetscInt it, PetscReal norm, void* context);
  void set_default_preconditioner(MPI_Comm comm, const std::string& prefix);

  MPI_Comm comm_;
  petsc::LinearSolver ksp_;
  Progress progress_;
  PreconditionerReuse reuse_;
  double tightest_ = 0.0;  // as set, by default or from the command line
  PetscInt max_iterations_ = 0;
};

}  // namespace naris::nonlinear
