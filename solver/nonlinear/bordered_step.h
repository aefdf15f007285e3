#pragma once
// Newton's step on the bordered system of pseudo-arclength continuation (options.h:
// ArclengthConstraint) by block elimination: J a = −R and J b = −∂R/∂Re (a difference
// quotient) with the same preconditioner, then δRe from the constraint, which is linear, and
// δu = a + δRe b.
#include <petscksp.h>

#include <vector>

#include "solver/nonlinear/linear_solver.h"
#include "solver/nonlinear/options.h"
#include "solver/ns/oseen_system.h"

namespace naris::nonlinear {

// ⟨a, b⟩ of the arclength constraint: the mean over the whole mesh's nodes of a_u·b_u, from
// each rank's owned nodes (the first `numbering.owned` of its piece). Collective.
double velocity_inner_product(const ns::FlowField& a, const ns::FlowField& b,
                              const parallel::NodeNumbering& numbering, MPI_Comm comm);

class BorderedStep {
 public:
  BorderedStep(const ArclengthConstraint& constraint, ns::OseenSystem& system,
               const parallel::NodeNumbering& numbering, MPI_Comm comm);

  // Before the iterate's own assembly (which overwrites the system): R at a slightly larger Re.
  void sample_residual_above(const ns::FlowField& field, double reynolds,
                             const ns::BodyForce& force);
  // After it: ∂R/∂Re, zero on the fixed rows like R.
  void differentiate(double reynolds, const std::vector<PetscInt>& fixed_rows);
  // Whether the iterate lies on the step's hyperplane (a damped step leaves part unmet).
  bool on_constraint(const ns::FlowField& field, double reynolds) const;
  // The second solve, J b = −∂R/∂Re, and δRe; δ (the system's solution, J a = −R) becomes
  // a + δRe b. Returns δRe; `solve` gets the second solve's reason and iterations added.
  double correct(LinearSolver& linear, const ns::FlowField& field, double reynolds, double eta,
                 bool newton, LinearSolve& solve, NonlinearReport& report);
  // At convergence after a Newton step: the branch's unit tangent into the report.
  void report_tangent(const ns::FlowField& field, double reynolds, NonlinearReport& report);

 private:
  // N(u, Re): how far the iterate is off the step's hyperplane.
  double constraint_residual(const ns::FlowField& u, double reynolds) const;
  double inner_product(const ns::FlowField& t, Vec v) const;

  const ArclengthConstraint& c_;
  ns::OseenSystem& system_;
  const parallel::NodeNumbering& numbering_;
  MPI_Comm comm_;
  petsc::Vector sensitivity_, sensitivity_solution_;  // ∂R/∂Re and b
  bool tangent_known_ = false;                        // the last b is du/dRe
};

}  // namespace naris::nonlinear
