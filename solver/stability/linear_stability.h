#pragma once
// Linear stability of a steady solution: the eigenvalues λ of J v = λ M v nearest zero, J
// Newton's whole derivative of the discrete residual (the solver's own operator) and M the
// velocity's lumped mass. A small perturbation v evolves as M v' = −J v, so it grows where
// Re λ < 0; a real λ through zero is where the steady branch folds or splits, a complex pair
// where it turns unsteady (Hopf). SLEPc's Krylov–Schur on the shift-and-invert at 0, each solve
// GMRES preconditioned by MUMPS's LU of the assembled part of J.
#include <complex>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/flow_problem.h"
#include "solver/parallel/partition.h"

namespace naris::stability {

struct StabilityOptions {
  int modes = 4;                      // eigenvalues wanted
  double tolerance = 1e-8;            // SLEPc's relative tolerance of each pair
  std::string prefix = "stability_";  // for SLEPc and PETSc options (-stability_eps_…)
};

struct Mode {
  std::complex<double> eigenvalue;  // λ, in units of U_in/d_in
  double residual = 0.0;            // ‖J v − λ M v‖ / ‖λ M v‖ as SLEPc reports it
};

// The steady `field` on this rank's piece (parallel/partition.h), of `problem`; the
// `options.modes` nearest zero (one more where the last is half of a complex pair; fewer if
// SLEPc converged fewer), then any other converged mode that grows (Re λ < 0), sorted by |λ|.
// Collective over the problem's communicator.
std::vector<Mode> leading_modes(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                                const ns::FlowProblem& problem, const ns::FlowField& field,
                                const StabilityOptions& options = {});

}  // namespace naris::stability
