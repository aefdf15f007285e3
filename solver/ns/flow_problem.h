#pragma once
// The steady incompressible Navier–Stokes problem in nondimensional form: the Reynolds number
// (ν = 1/Re), the body force, the Dirichlet data, the outlet's backflow stabilization, and the
// ranks that share it.
#include <mpi.h>

#include "solver/ns/flow_field.h"

namespace naris::ns {

// Outflow stabilization (Bazilevs et al. 2009) on one patch, the outlet: −β ∫ (u·n)₋ u·w.
struct BackflowStabilization {
  int patch = -1;  // −1: none
  double beta = 1.0;
};

struct FlowProblem {
  double reynolds = 1.0;
  BodyForce force;  // may be empty
  DirichletConditions conditions;
  BackflowStabilization backflow;
  MPI_Comm communicator = MPI_COMM_NULL;  // MPI_COMM_NULL: PETSC_COMM_WORLD
};

}  // namespace naris::ns
