#pragma once
// One sweep of the segregated (SIMPLE-type) scheme of FiDAP (Haroutunian, Engelman & Hasbani
// 1993) on the coupled correction equation
//   [A  Bᵀ] [δu]   [r_u]
//   [B  C ] [δp] = [r_p]
// assembled with the velocity and pressure of each node interleaved (u, v, w, p): the momentum
// equations with the pressure correction frozen, A' δu* = r_u (A' = A with its diagonal D
// divided by α_u, implicit under-relaxation); then the pressure correction from continuity with
// A'⁻¹ ≈ D'⁻¹, (C − B D'⁻¹ Bᵀ) δp = r_p − B δu*; then δu = δu* − D'⁻¹ Bᵀ δp and δp ← α_p δp.
// The momentum and pressure solves are GMRES on algebraic multigrid (hypre BoomerAMG for
// momentum, PETSc's GAMG for pressure) to 1e-2,
// or one V-cycle each when the sweep preconditions a Krylov method on the coupled system (a
// fixed linear map); options prefixes <prefix>momentum_ and <prefix>pressure_.
#include <petscksp.h>

#include <string>

#include "solver/parallel/petsc.h"

namespace naris::ns {

class SegregatedStep {
 public:
  // `M` gives the layout (an AIJ matrix of 4 interleaved fields per node, owned rows in whole
  // nodes); α_u and α_p in (0, 1].
  SegregatedStep(Mat M, const std::string& prefix, double alpha_u, double alpha_p,
                 bool v_cycles = false);

  // δ ≈ M⁻¹ r for the current M (same nonzero pattern every call): setup(M) then solve.
  void apply(Mat M, Vec r, Vec delta);
  void setup(Mat M);  // blocks, D'⁻¹ and the pressure operator of M
  void solve(Vec r, Vec delta);
  // Makes `pc` a shell that applies this sweep (set up from its preconditioning matrix).
  void use_as_preconditioner(PC pc);
  int momentum_iterations() const { return momentum_its_; }
  int pressure_iterations() const { return pressure_its_; }

 private:
  double alpha_u_, alpha_p_;
  bool first_ = true;
  int momentum_its_ = 0, pressure_its_ = 0;
  petsc::IndexSet velocity_, pressure_;
  petsc::Matrix A_, Bt_, B_, C_, scaled_Bt_, S_;
  petsc::Vector d_inv_, du_, dp_, rhs_p_, work_u_;
  petsc::LinearSolver momentum_, pressure_solver_;
};

}  // namespace naris::ns
