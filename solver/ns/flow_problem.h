#pragma once
// The steady incompressible Navier–Stokes problem in nondimensional form: the Reynolds number
// (ν = 1/Re), the body force, the Dirichlet data, the outlet's backflow stabilization, and the
// ranks that share it.
#include <mpi.h>

#include <vector>

#include "solver/ns/flow_field.h"

namespace naris::ns {

// The term −β ∫ (u·n)₋ u·w (backflow.h) on the natural patches. On an outlet, β = 1 stabilizes
// backflow (Bazilevs et al. 2009); on an opening to still air, β = ½ makes the traction
// p = −½ (u·n)², the total pressure of air drawn in from rest (docs/method/boundary-conditions.md).
struct BackflowStabilization {
  struct Patch {
    int patch = -1;
    double beta = 1.0;
  };
  std::vector<Patch> patches;
  // Width of the switch's smoothing (negative_part), in units of the mean inlet speed; 0: none.
  double smoothing = 0.0;
  // β on `patch`, 0 where the term is not applied.
  double beta(int patch) const {
    for (const Patch& p : patches)
      if (p.patch == patch) return p.beta;
    return 0.0;
  }
};

struct FlowProblem {
  double reynolds = 1.0;
  BodyForce force;  // may be empty
  DirichletConditions conditions;
  BackflowStabilization backflow;
  MPI_Comm communicator = MPI_COMM_NULL;  // MPI_COMM_NULL: PETSC_COMM_WORLD
};

}  // namespace naris::ns
