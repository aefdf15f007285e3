#include "solver/stability/linear_stability.h"

#include <slepceps.h>

#include <algorithm>

#include "core/error.h"
#include "solver/ns/oseen_system.h"
#include "solver/parallel/petsc.h"

namespace naris::stability {
namespace {

using petsc::check;

// SLEPc on top of the running PETSc: initialized here unless someone did, finalized with it.
class SlepcSession {
 public:
  SlepcSession() {
    PetscBool up = PETSC_FALSE;
    check(SlepcInitialized(&up), "SlepcInitialized");
    if (!up) {
      check(SlepcInitialize(nullptr, nullptr, nullptr, nullptr), "SlepcInitialize");
      owner_ = true;
    }
  }
  ~SlepcSession() {
    if (owner_) SlepcFinalize();
  }
  SlepcSession(const SlepcSession&) = delete;
  SlepcSession& operator=(const SlepcSession&) = delete;

 private:
  bool owner_ = false;
};

using Eigensolver = petsc::Handle<EPS, EPSDestroy>;

}  // namespace

std::vector<Mode> leading_modes(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                                const ns::FlowProblem& problem, const ns::FlowField& field,
                                const StabilityOptions& options) {
  if (options.modes < 1) fail("stability: ask for at least one eigenvalue ({})", options.modes);
  const SlepcSession session;
  const MPI_Comm comm =
      problem.communicator == MPI_COMM_NULL ? PETSC_COMM_WORLD : problem.communicator;
  ns::OseenSystem system(piece, numbering, comm, options.prefix, problem.backflow, MATBAIJ);
  const std::vector<PetscInt> rows = system.fixed_rows(problem.conditions);
  system.use_newton_operator(rows);
  const double nu = 1.0 / problem.reynolds;
  system.assemble(field.velocity, field.pressure, nu, problem.force, ns::Linearization::newton);
  check(MatZeroRows(system.matrix(), static_cast<PetscInt>(rows.size()), rows.data(), 1.0, nullptr,
                    nullptr),
        "MatZeroRows");
  Mat jacobian = system.newton_operator(field.velocity, nu);

  // M: the velocity's lumped mass, nothing on the pressure and the fixed rows (their
  // eigenvalues are infinite and never near zero).
  petsc::Vector mass;
  check(VecDuplicate(system.solution(), mass.out()), "VecDuplicate");
  system.velocity_mass(mass);
  const std::vector<PetscScalar> zeros(rows.size(), 0.0);
  check(VecSetValues(mass, static_cast<PetscInt>(rows.size()), rows.data(), zeros.data(),
                     INSERT_VALUES),
        "VecSetValues");
  check(VecAssemblyBegin(mass), "VecAssemblyBegin");
  check(VecAssemblyEnd(mass), "VecAssemblyEnd");
  petsc::Matrix mass_matrix;
  PetscInt first = 0, end = 0;
  check(VecGetOwnershipRange(mass, &first, &end), "VecGetOwnershipRange");
  check(MatCreateAIJ(comm, end - first, end - first, PETSC_DETERMINE, PETSC_DETERMINE, 1, nullptr,
                     0, nullptr, mass_matrix.out()),
        "MatCreateAIJ");
  check(MatDiagonalSet(mass_matrix, mass, INSERT_VALUES), "MatDiagonalSet");

  Eigensolver eps;
  check(EPSCreate(comm, eps.out()), "EPSCreate");
  check(EPSSetOperators(eps, jacobian, mass_matrix), "EPSSetOperators");
  check(EPSSetProblemType(eps, EPS_GNHEP), "EPSSetProblemType");
  check(EPSSetDimensions(eps, options.modes, PETSC_DEFAULT, PETSC_DEFAULT), "EPSSetDimensions");
  check(EPSSetTolerances(eps, options.tolerance, 300), "EPSSetTolerances");
  check(EPSSetTarget(eps, 0.0), "EPSSetTarget");
  check(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE), "EPSSetWhichEigenpairs");
  ST st = nullptr;
  check(EPSGetST(eps, &st), "EPSGetST");
  check(STSetType(st, STSINVERT), "STSetType");
  // The shell J is inverted by GMRES on the LU of its assembled part, which the solver's
  // Newton steps show to be a close preconditioner.
  check(STSetPreconditionerMat(st, system.matrix()), "STSetPreconditionerMat");
  KSP ksp = nullptr;
  check(STGetKSP(st, &ksp), "STGetKSP");
  check(KSPSetType(ksp, KSPGMRES), "KSPSetType");
  check(KSPGMRESSetRestart(ksp, 100), "KSPGMRESSetRestart");
  check(KSPSetTolerances(ksp, 1e-3 * options.tolerance, 1e-300, PETSC_DEFAULT, 1000),
        "KSPSetTolerances");
  PC pc = nullptr;
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  check(PCSetType(pc, PCLU), "PCSetType");
  check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
  check(EPSSetOptionsPrefix(eps, options.prefix.c_str()), "EPSSetOptionsPrefix");
  check(EPSSetFromOptions(eps), "EPSSetFromOptions");
  check(EPSSolve(eps), "EPSSolve");

  PetscInt converged = 0;
  check(EPSGetConverged(eps, &converged), "EPSGetConverged");
  std::vector<Mode> modes;
  for (PetscInt i = 0; i < converged; ++i) {
    PetscScalar re = 0.0, im = 0.0;
    check(EPSGetEigenvalue(eps, i, &re, &im), "EPSGetEigenvalue");
    PetscReal error = 0.0;
    check(EPSComputeError(eps, i, EPS_ERROR_RELATIVE, &error), "EPSComputeError");
    modes.push_back({{re, im}, error});
  }
  std::sort(modes.begin(), modes.end(), [](const Mode& a, const Mode& b) {
    return std::abs(a.eigenvalue) < std::abs(b.eigenvalue);
  });
  // SLEPc may converge more than asked; keep the nearest, with a complex pair kept whole, and
  // every growing one (a perturbation that grows is never dropped).
  std::size_t kept = std::min(modes.size(), static_cast<std::size_t>(options.modes));
  if (kept > 0 && kept < modes.size() && modes[kept - 1].eigenvalue.imag() != 0.0 &&
      std::abs(modes[kept].eigenvalue - std::conj(modes[kept - 1].eigenvalue)) <=
          1e-8 * std::abs(modes[kept].eigenvalue))
    ++kept;
  modes.erase(std::remove_if(modes.begin() + static_cast<std::ptrdiff_t>(kept), modes.end(),
                             [](const Mode& mode) { return mode.eigenvalue.real() >= 0.0; }),
              modes.end());
  return modes;
}

}  // namespace naris::stability
