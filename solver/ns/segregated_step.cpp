#include "solver/ns/segregated_step.h"

#include <vector>

#include "core/error.h"

namespace naris::ns {

using petsc::check;

namespace {

void setup_solver(petsc::LinearSolver& ksp, MPI_Comm comm, const std::string& prefix, bool v_cycle,
                  bool boomeramg) {
  check(KSPCreate(comm, ksp.out()), "KSPCreate");
  check(KSPSetOptionsPrefix(ksp, prefix.c_str()), "KSPSetOptionsPrefix");
  if (v_cycle) {
    // Inside a Krylov method the sweep must be a fixed linear map: one V-cycle.
    check(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
  } else {
    check(KSPSetType(ksp, KSPGMRES), "KSPSetType");
    check(KSPSetPCSide(ksp, PC_RIGHT), "KSPSetPCSide");
    // Inexact: the outer iteration corrects what a sweep leaves.
    check(KSPSetTolerances(ksp, 1e-2, 1e-30, PETSC_DEFAULT, 500), "KSPSetTolerances");
  }
  PC pc = nullptr;
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  if (boomeramg) {
    check(PCSetType(pc, PCHYPRE), "PCSetType");
    check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
  } else {
    check(PCSetType(pc, PCGAMG), "PCSetType");
  }
  check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
}

}  // namespace

SegregatedStep::SegregatedStep(Mat M, const std::string& prefix, double alpha_u, double alpha_p,
                               bool v_cycles)
    : alpha_u_(alpha_u), alpha_p_(alpha_p) {
  if (!(alpha_u > 0.0 && alpha_u <= 1.0 && alpha_p > 0.0 && alpha_p <= 1.0))
    fail("segregated relaxation factors must lie in (0, 1] (got {} and {})", alpha_u, alpha_p);
  MPI_Comm comm = PETSC_COMM_SELF;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(M), &comm), "PetscObjectGetComm");
  PetscInt lo = 0, hi = 0;
  check(MatGetOwnershipRange(M, &lo, &hi), "MatGetOwnershipRange");
  std::vector<PetscInt> u, p;
  u.reserve(static_cast<std::size_t>(3 * (hi - lo) / 4));
  p.reserve(static_cast<std::size_t>((hi - lo) / 4));
  for (PetscInt row = lo; row < hi; ++row) (row % 4 == 3 ? p : u).push_back(row);
  check(ISCreateGeneral(comm, static_cast<PetscInt>(u.size()), u.data(), PETSC_COPY_VALUES,
                        velocity_.out()),
        "ISCreateGeneral");
  check(ISCreateGeneral(comm, static_cast<PetscInt>(p.size()), p.data(), PETSC_COPY_VALUES,
                        pressure_.out()),
        "ISCreateGeneral");
  // BoomerAMG for momentum; PETSc's smoothed aggregation for the pressure operator, where
  // BoomerAMG's V-cycle returns NaN (C − B D⁻¹ Bᵀ is no M-matrix;
  // docs/results/solver-choices.md).
  setup_solver(momentum_, comm, prefix + "momentum_", v_cycles, true);
  setup_solver(pressure_solver_, comm, prefix + "pressure_", v_cycles, false);
}

void SegregatedStep::apply(Mat M, Vec r, Vec delta) {
  setup(M);
  solve(r, delta);
}

void SegregatedStep::setup(Mat M) {
  const MatReuse reuse = first_ ? MAT_INITIAL_MATRIX : MAT_REUSE_MATRIX;
  auto sub = [&](IS rows, IS cols, petsc::Matrix& out) {
    Mat m = out.get();
    check(MatCreateSubMatrix(M, rows, cols, reuse, &m), "MatCreateSubMatrix");
    if (first_) out = petsc::Matrix(m);
  };
  sub(velocity_, velocity_, A_);
  sub(velocity_, pressure_, Bt_);
  sub(pressure_, velocity_, B_);
  sub(pressure_, pressure_, C_);
  if (first_) {
    check(MatCreateVecs(A_, du_.out(), work_u_.out()), "MatCreateVecs");
    check(VecDuplicate(du_, d_inv_.out()), "VecDuplicate");
    check(MatCreateVecs(C_, dp_.out(), rhs_p_.out()), "MatCreateVecs");
  }
  // Implicit under-relaxation: A' = A + (1/α_u − 1) D.
  check(MatGetDiagonal(A_, d_inv_), "MatGetDiagonal");
  check(VecScale(d_inv_, 1.0 / alpha_u_), "VecScale");
  check(MatDiagonalSet(A_, d_inv_, INSERT_VALUES), "MatDiagonalSet");
  check(VecReciprocal(d_inv_), "VecReciprocal");

  // The pressure operator C − B D'⁻¹ Bᵀ, positive definite: B ≈ −(Bᵀ)ᵀ (divergence against
  // gradient) and C is PSPG's τ ∇q·∇p. C ⊂ the pattern of B Bᵀ: both couple nodes of a cell.
  if (first_) {
    check(MatDuplicate(Bt_, MAT_COPY_VALUES, scaled_Bt_.out()), "MatDuplicate");
  } else {
    check(MatCopy(Bt_, scaled_Bt_, SAME_NONZERO_PATTERN), "MatCopy");
  }
  check(MatDiagonalScale(scaled_Bt_, d_inv_, nullptr), "MatDiagonalScale");
  {
    Mat s = S_.get();
    check(MatMatMult(B_, scaled_Bt_, reuse, PETSC_DEFAULT, &s), "MatMatMult");
    if (first_) S_ = petsc::Matrix(s);
  }
  check(MatScale(S_, -1.0), "MatScale");
  check(MatAXPY(S_, 1.0, C_, SUBSET_NONZERO_PATTERN), "MatAXPY");
  check(KSPSetOperators(momentum_, A_, A_), "KSPSetOperators");
  check(KSPSetOperators(pressure_solver_, S_, S_), "KSPSetOperators");
  first_ = false;
}

void SegregatedStep::solve(Vec r, Vec delta) {
  Vec ru = nullptr, rp = nullptr;
  check(VecGetSubVector(r, velocity_, &ru), "VecGetSubVector");
  check(VecGetSubVector(r, pressure_, &rp), "VecGetSubVector");
  // Momentum with the pressure correction frozen.
  check(KSPSolve(momentum_, ru, du_), "KSPSolve");
  // Continuity: (C − B D'⁻¹ Bᵀ) δp = r_p − B δu*.
  check(MatMult(B_, du_, rhs_p_), "MatMult");
  check(VecAYPX(rhs_p_, -1.0, rp), "VecAYPX");
  check(KSPSolve(pressure_solver_, rhs_p_, dp_), "KSPSolve");
  check(VecRestoreSubVector(r, velocity_, &ru), "VecRestoreSubVector");
  check(VecRestoreSubVector(r, pressure_, &rp), "VecRestoreSubVector");
  for (KSP k : {momentum_.get(), pressure_solver_.get()}) {
    KSPConvergedReason reason;
    check(KSPGetConvergedReason(k, &reason), "KSPGetConvergedReason");
    if (reason < 0 && reason != KSP_DIVERGED_ITS)
      fail("the segregated {} solve failed ({})", k == momentum_.get() ? "momentum" : "pressure",
           KSPConvergedReasons[reason]);
  }
  PetscInt its = 0;
  check(KSPGetIterationNumber(momentum_, &its), "KSPGetIterationNumber");
  momentum_its_ = static_cast<int>(its);
  check(KSPGetIterationNumber(pressure_solver_, &its), "KSPGetIterationNumber");
  pressure_its_ = static_cast<int>(its);

  // Velocity correction δu = δu* − D'⁻¹ Bᵀ δp; relaxed pressure.
  check(MatMult(Bt_, dp_, work_u_), "MatMult");
  check(VecPointwiseMult(work_u_, work_u_, d_inv_), "VecPointwiseMult");
  check(VecAXPY(du_, -1.0, work_u_), "VecAXPY");
  check(VecScale(dp_, alpha_p_), "VecScale");
  Vec out = nullptr;
  check(VecGetSubVector(delta, velocity_, &out), "VecGetSubVector");
  check(VecCopy(du_, out), "VecCopy");
  check(VecRestoreSubVector(delta, velocity_, &out), "VecRestoreSubVector");
  check(VecGetSubVector(delta, pressure_, &out), "VecGetSubVector");
  check(VecCopy(dp_, out), "VecCopy");
  check(VecRestoreSubVector(delta, pressure_, &out), "VecRestoreSubVector");
}

namespace {

PetscErrorCode shell_setup(PC pc) {
  SegregatedStep* step = nullptr;
  Mat A = nullptr, P = nullptr;
  PetscCall(PCShellGetContext(pc, &step));
  PetscCall(PCGetOperators(pc, &A, &P));
  try {
    step->setup(P);
  } catch (const Error&) {
    return PETSC_ERR_LIB;
  }
  return 0;
}

PetscErrorCode shell_apply(PC pc, Vec x, Vec y) {
  SegregatedStep* step = nullptr;
  PetscCall(PCShellGetContext(pc, &step));
  try {
    step->solve(x, y);
  } catch (const Error&) {
    return PETSC_ERR_LIB;
  }
  return 0;
}

}  // namespace

void SegregatedStep::use_as_preconditioner(PC pc) {
  check(PCSetType(pc, PCSHELL), "PCSetType");
  check(PCShellSetContext(pc, this), "PCShellSetContext");
  check(PCShellSetSetUp(pc, shell_setup), "PCShellSetSetUp");
  check(PCShellSetApply(pc, shell_apply), "PCShellSetApply");
  check(PCShellSetName(pc, "segregated (SIMPLE) sweep"), "PCShellSetName");
}

}  // namespace naris::ns
