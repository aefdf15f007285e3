#include "solver/nonlinear/bordered_step.h"

#include <fmt/format.h>

#include <cmath>

namespace naris::nonlinear {

using petsc::check;

namespace {
// The relative increment of Re of the difference quotient: where a residual smooth in ν is
// accurate to ~1e-6 and rounding costs ~1e-10.
constexpr double kReynoldsDifference = 1e-6;
}  // namespace

double velocity_inner_product(const ns::FlowField& a, const ns::FlowField& b,
                              const parallel::NodeNumbering& numbering, MPI_Comm comm) {
  double sum = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering.owned); ++i)
    sum += a.velocity[i].dot(b.velocity[i]);
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  return sum / static_cast<double>(numbering.global_nodes);
}

BorderedStep::BorderedStep(const ArclengthConstraint& constraint, ns::OseenSystem& system,
                           const parallel::NodeNumbering& numbering, MPI_Comm comm)
    : c_(constraint), system_(system), numbering_(numbering), comm_(comm) {
  check(VecDuplicate(system.solution(), sensitivity_.out()), "VecDuplicate");
  check(VecDuplicate(system.solution(), sensitivity_solution_.out()), "VecDuplicate");
}

void BorderedStep::sample_residual_above(const ns::FlowField& field, double reynolds,
                                         const ns::BodyForce& force) {
  system_.assemble(field.velocity, field.pressure, 1.0 / (reynolds * (1 + kReynoldsDifference)),
                   force, ns::Linearization::picard_residual);
  check(VecCopy(system_.residual(), sensitivity_), "VecCopy");
}

void BorderedStep::differentiate(double reynolds, const std::vector<PetscInt>& fixed_rows) {
  const double h = reynolds * kReynoldsDifference;
  check(VecAXPBY(sensitivity_, -1.0 / h, 1.0 / h, system_.residual()), "VecAXPBY");
  const std::vector<double> zeros(fixed_rows.size(), 0.0);
  check(VecSetValues(sensitivity_, static_cast<PetscInt>(fixed_rows.size()), fixed_rows.data(),
                     zeros.data(), INSERT_VALUES),
        "VecSetValues");
  check(VecAssemblyBegin(sensitivity_), "VecAssemblyBegin");
  check(VecAssemblyEnd(sensitivity_), "VecAssemblyEnd");
}

double BorderedStep::inner_product(const ns::FlowField& t, Vec v) const {
  const PetscScalar* x = nullptr;
  check(VecGetArrayRead(v, &x), "VecGetArrayRead");
  double sum = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering_.owned); ++i)
    for (int c = 0; c < 3; ++c) sum += t.velocity[i][c] * x[4 * i + static_cast<std::size_t>(c)];
  check(VecRestoreArrayRead(v, &x), "VecRestoreArrayRead");
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return sum / static_cast<double>(numbering_.global_nodes);
}

double BorderedStep::constraint_residual(const ns::FlowField& u, double reynolds) const {
  double sum = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering_.owned); ++i)
    sum += c_.tangent.velocity[i].dot(u.velocity[i] - c_.origin.velocity[i]);
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return sum / static_cast<double>(numbering_.global_nodes) +
         c_.tangent_reynolds * (reynolds - c_.origin_reynolds) /
             (c_.origin_reynolds * c_.origin_reynolds) -
         c_.step;
}

bool BorderedStep::on_constraint(const ns::FlowField& field, double reynolds) const {
  return std::abs(constraint_residual(field, reynolds)) <= 1e-6 * std::abs(c_.step);
}

double BorderedStep::correct(LinearSolver& linear, const ns::FlowField& field, double reynolds,
                             double eta, bool newton, LinearSolve& solve, NonlinearReport& report) {
  check(VecAXPBY(system_.rhs(), -1.0, 0.0, sensitivity_), "VecAXPBY");
  const LinearSolve second = linear.solve_again(system_.rhs(), sensitivity_solution_, eta);
  // b = du/dRe only with Newton's derivative; after a Picard step it is not the tangent.
  tangent_known_ = newton;
  solve.reason = second.reason;
  report.linear_iterations += second.iterations;
  solve.description += fmt::format(" + {} for ∂R/∂Re", second.iterations);
  // δRe from the constraint, which is linear: N + ⟨t, a + δRe b⟩ + t_Re δRe / Re₁² = 0.
  const double n_now = constraint_residual(field, reynolds);
  const double ta = inner_product(c_.tangent, system_.solution()),
               tb = inner_product(c_.tangent, sensitivity_solution_);
  const double weight = 1.0 / (c_.origin_reynolds * c_.origin_reynolds);
  const double reynolds_step = -(n_now + ta) / (weight * c_.tangent_reynolds + tb);
  check(VecAXPY(system_.solution(), reynolds_step, sensitivity_solution_), "VecAXPY");
  return reynolds_step;
}

// The tangent from b = du/dRe (J b = −∂R/∂Re), not from the secant through two points: points
// converged to a loose tolerance carry errors as large as a short step, and the secant through
// them can reverse and claim a turn that is not there.
void BorderedStep::report_tangent(const ns::FlowField& field, double reynolds, NonlinearReport& r) {
  if (!tangent_known_) return;
  r.tangent = field;
  system_.gather(sensitivity_solution_, r.tangent);
  double length = std::sqrt(velocity_inner_product(r.tangent, r.tangent, numbering_, comm_) +
                            1.0 / (reynolds * reynolds));
  if (velocity_inner_product(r.tangent, c_.tangent, numbering_, comm_) +
          c_.tangent_reynolds / (reynolds * reynolds) <
      0.0)
    length = -length;
  for (std::size_t k = 0; k < r.tangent.pressure.size(); ++k) {
    r.tangent.velocity[k] /= length;
    r.tangent.pressure[k] /= length;
  }
  r.tangent_reynolds = 1.0 / length;
}

}  // namespace naris::nonlinear
