#include "solver/nonlinear/linear_solver.h"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "solver/ns/segregated_step.h"

namespace naris::nonlinear {

using petsc::check;

LinearSolver::LinearSolver(MPI_Comm comm, const NonlinearOptions& options,
                           ns::SegregatedStep* sweep)
    : comm_(comm),
      progress_{Stopwatch(), options.progress_seconds},
      // Any preconditioner of the coupled system may be kept; the segregated sweeps set theirs
      // up themselves.
      reuse_(options.reuse_preconditioner && options.scheme == NonlinearOptions::Scheme::coupled) {
  check(KSPCreate(comm, ksp_.out()), "KSPCreate");
  check(KSPSetOptionsPrefix(ksp_, options.options_prefix.c_str()), "KSPSetOptionsPrefix");
  // Each solve is inexact: it stops when the residual of the correction equation has fallen by
  // the forcing term (forcing_term.h); the outer iteration measures the true residual and
  // corrects what is left. `-ns_ksp_type preonly -ns_pc_type lu` gives a direct solve.
  check(KSPSetType(ksp_, KSPGMRES), "KSPSetType");
  check(KSPGMRESSetRestart(ksp_, 200), "KSPGMRESSetRestart");
  // Right preconditioning: GMRES then minimizes the true residual, which is what the tolerance
  // is meant for (docs/results/solver-choices.md).
  check(KSPSetPCSide(ksp_, PC_RIGHT), "KSPSetPCSide");
  check(KSPSetTolerances(ksp_, options.linear_tolerance, 1e-30, PETSC_DEFAULT, 5000),
        "KSPSetTolerances");
  PC pc = nullptr;
  check(KSPGetPC(ksp_, &pc), "KSPGetPC");
  if (options.scheme == NonlinearOptions::Scheme::segregated_krylov)
    sweep->use_as_preconditioner(pc);
  else
    set_default_preconditioner(comm, options.options_prefix);
  if (options.progress_seconds > 0.0)
    check(KSPMonitorSet(ksp_, &LinearSolver::monitor, &progress_, nullptr), "KSPMonitorSet");
  check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
  PetscReal tightest = 0.0;
  check(KSPGetTolerances(ksp_, &tightest, nullptr, nullptr, &max_iterations_), "KSPGetTolerances");
  tightest_ = tightest;
}

// ILU(1) of the 4×4-block matrix in reverse Cuthill–McKee order on one rank; on several,
// additive Schwarz with one layer of overlap and the same ILU(1) on each rank's block, set in
// the options database so that the command line still overrides it (`-ns_pc_type bjacobi` for
// the leaner one). The choices' measurements: docs/results/solver-choices.md.
void LinearSolver::set_default_preconditioner(MPI_Comm comm, const std::string& prefix) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  PC pc = nullptr;
  check(KSPGetPC(ksp_, &pc), "KSPGetPC");
  if (ranks == 1) {
    check(PCSetType(pc, PCILU), "PCSetType");
    check(PCFactorSetLevels(pc, 1), "PCFactorSetLevels");
    check(PCFactorSetMatOrderingType(pc, MATORDERINGRCM), "PCFactorSetMatOrderingType");
    return;
  }
  check(PCSetType(pc, PCASM), "PCSetType");
  check(PCASMSetOverlap(pc, 1), "PCASMSetOverlap");
  for (const auto& [name, value] :
       {std::pair{"sub_pc_type", "ilu"}, std::pair{"sub_pc_factor_levels", "1"},
        std::pair{"sub_pc_factor_mat_ordering_type", "rcm"}})
    petsc::set_default_option("-" + prefix + name, value);
}

PetscErrorCode LinearSolver::monitor(KSP solver, PetscInt it, PetscReal norm, void* context) {
  auto& p = *static_cast<Progress*>(context);
  if (it == 0) {
    p = {Stopwatch(), p.interval, 0.0, norm};
    return 0;
  }
  const double now = p.clock.seconds();
  if (now - p.last < p.interval) return 0;
  p.last = now;
  KSPType type = nullptr;
  PetscCall(KSPGetType(solver, &type));
  log_line(fmt::format("      {} {:5d}: residual {:.2e} of the solve's first, {:.0f} s", type,
                       static_cast<int>(it), norm / p.start_norm, now));
  return 0;
}

LinearSolve LinearSolver::solve(LinearProblem kind, Mat op, Mat matrix, Vec b, Vec delta,
                                double eta, NonlinearReport& report) {
  LinearSolve out;
  PetscInt its = 0, abandoned = 0;          // abandoned: those of a kept preconditioner's try
  const double decades = -std::log10(eta);  // the reduction asked for
  bool rebuilt = false;
  for (bool rebuild = !reuse_.keeps(kind);; rebuild = true) {
    check(KSPSetOperators(ksp_, op, matrix), "KSPSetOperators");
    check(KSPSetReusePreconditioner(ksp_, rebuild ? PETSC_FALSE : PETSC_TRUE),
          "KSPSetReusePreconditioner");
    check(KSPSetTolerances(
              ksp_, eta, PETSC_DEFAULT, PETSC_DEFAULT,
              rebuild ? max_iterations_
                      : std::min<PetscInt>(max_iterations_, reuse_.iteration_budget(decades))),
          "KSPSetTolerances");
    // The work of the factorization and of the solve in floating-point operations as PETSc
    // counts them, not in seconds: the counts are the same on every run, so whether a
    // preconditioner is kept, and with it the path of the iteration, does not depend on the
    // machine's load.
    PetscLogDouble start = 0.0, set_up = 0.0, solved = 0.0;
    check(PetscGetFlops(&start), "PetscGetFlops");
    check(KSPSetUp(ksp_), "KSPSetUp");  // the factorization, when it is rebuilt
    // Additive Schwarz factors its blocks here; otherwise inside the first solve.
    check(KSPSetUpOnBlocks(ksp_), "KSPSetUpOnBlocks");
    check(PetscGetFlops(&set_up), "PetscGetFlops");
    check(KSPSolve(ksp_, b, delta), "KSPSolve");
    check(PetscGetFlops(&solved), "PetscGetFlops");
    check(KSPGetConvergedReason(ksp_, &out.reason), "KSPGetConvergedReason");
    check(KSPGetIterationNumber(ksp_, &its), "KSPGetIterationNumber");
    report.linear_iterations += static_cast<int>(its);
    // The ranks' shares differ; they must still decide alike.
    double work[2] = {set_up - start, solved - set_up};
    MPI_Allreduce(MPI_IN_PLACE, work, 2, MPI_DOUBLE, MPI_MAX, comm_);
    if (rebuild) {
      reuse_.built(kind, work[0], work[1], static_cast<int>(its), decades);
      ++report.preconditioner_builds;
      rebuilt = true;
    } else {
      reuse_.kept(work[1], static_cast<int>(its), decades);
      abandoned = its;
    }
    if (out.reason >= 0 || rebuild) break;
    reuse_.abandoned();
  }
  out.iterations = static_cast<int>(its);
  out.description = fmt::format(
      "{} linear iterations{}", its,
      !rebuilt        ? " (preconditioner kept)"
      : abandoned > 0 ? fmt::format(" (after {} with the kept preconditioner)", abandoned)
                      : "");
  return out;
}

LinearSolve LinearSolver::solve_again(Vec b, Vec x, double eta) {
  LinearSolve out;
  check(KSPSetReusePreconditioner(ksp_, PETSC_TRUE), "KSPSetReusePreconditioner");
  check(KSPSetTolerances(ksp_, eta, PETSC_DEFAULT, PETSC_DEFAULT, max_iterations_),
        "KSPSetTolerances");
  check(KSPSolve(ksp_, b, x), "KSPSolve");
  PetscInt its = 0;
  check(KSPGetIterationNumber(ksp_, &its), "KSPGetIterationNumber");
  check(KSPGetConvergedReason(ksp_, &out.reason), "KSPGetConvergedReason");
  out.iterations = static_cast<int>(its);
  return out;
}

}  // namespace naris::nonlinear
