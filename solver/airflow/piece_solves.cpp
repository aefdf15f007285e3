#include "solver/airflow/piece_solves.h"

#include <fmt/format.h>
#include <petscsys.h>

#include <algorithm>

#include "core/csv.h"
#include "solver/nonlinear/bordered_step.h"
#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/ns/distributed_field.h"
#include "solver/ns/patch_integrals.h"

namespace naris::airflow {

PieceSolves::PieceSolves(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                         ns::FlowProblem problem, int inlet, int outlet, ns::DrivenPatch driven,
                         SolutionState scales, RunFiles files)
    : piece_(piece),
      numbering_(numbering),
      problem_(std::move(problem)),
      inlet_(inlet),
      outlet_(outlet),
      driven_(driven),
      scales_(scales),
      files_(std::move(files)) {
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank_);
}

ns::FlowField PieceSolves::solve(double reynolds, const nonlinear::NonlinearOptions& options,
                                 const ns::FlowField* initial,
                                 const nonlinear::ArclengthConstraint* constraint,
                                 nonlinear::NonlinearReport& report) {
  problem_.reynolds = reynolds;
  return nonlinear::solve_navier_stokes(piece_, numbering_, problem_, options, &report, initial,
                                        constraint);
}

double PieceSolves::inner_product(const ns::FlowField& a, const ns::FlowField& b) {
  return nonlinear::velocity_inner_product(a, b, numbering_, PETSC_COMM_WORLD);
}

SolutionState PieceSolves::state_at(const ns::FlowField& field, double reynolds) const {
  SolutionState s = scales_;
  s.field = ns::gather_field(field, numbering_, PETSC_COMM_WORLD, 0);
  s.reynolds = reynolds;
  return s;
}

void PieceSolves::checkpoint(double reynolds, const ns::FlowField& field,
                             const continuation::ContinuationState& state) {
  SolutionState s = state_at(field, reynolds);  // collective
  // The scalars; the earlier field gathered from the pieces, not copied.
  s.continuation = {.next_step = state.next_step,
                    .pseudo_time = state.pseudo_time,
                    .earlier_reynolds = state.earlier_reynolds,
                    .arclength_step = state.arclength_step};
  if (state.earlier_reynolds > 0.0)
    s.continuation.earlier = ns::gather_field(state.earlier, numbering_, PETSC_COMM_WORLD, 0);
  if (writer()) write_solution_h5(s, files_.checkpoint);
}

void PieceSolves::branch_point(double reynolds, const ns::FlowField& f, int newton_steps,
                               double arclength) {
  const double u = scales_.u_in * reynolds / scales_.target_reynolds;  // U_in at that Re, m/s
  branch_.add_row({fmt::format("{:.6f}", reynolds), fmt::format("{:.6e}", arclength),
                   fmt::format("{:.6f}", pressure_drop(f) * scales_.density * u * u),
                   fmt::format("{:.6f}", max_speed(f) * u), std::to_string(newton_steps)});
  if (writer()) branch_.write(files_.branch);
}

void PieceSolves::giving_up(const std::vector<continuation::ContinuationStep>& steps) {
  if (writer()) write_residual_history(steps, files_.residuals);
}

double PieceSolves::pressure_drop(const ns::FlowField& f) const {
  const ns::PatchIntegral in = ns::patch_integral(piece_, f.pressure, inlet_),
                          out = ns::patch_integral(piece_, f.pressure, outlet_);
  double sums[4] = {in.integral, in.area, out.integral, out.area};
  MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  return sums[0] / sums[1] - sums[2] / sums[3];
}

double PieceSolves::max_speed(const ns::FlowField& f) const {
  double m = 0.0;
  for (NodeId k = 0; k < numbering_.owned; ++k)
    m = std::max(m, f.velocity[static_cast<std::size_t>(k)].norm());
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  return m;
}

double PieceSolves::outlet_pressure(const ns::FlowField& f) const {
  const ns::PatchIntegral out = ns::patch_integral(piece_, f.pressure, outlet_);
  double sums[2] = {out.integral, out.area};
  MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  return sums[0] / sums[1];
}

double PieceSolves::flux_out(const ns::FlowField& f, int patch) const {
  double flux = ns::patch_flux(piece_, f.velocity, patch);
  MPI_Allreduce(MPI_IN_PLACE, &flux, 1, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  return flux;
}

std::vector<double> PieceSolves::opening_inflows(const ns::FlowField& f,
                                                 const std::vector<int>& opening,
                                                 std::size_t openings,
                                                 const std::vector<std::size_t>& face_index) const {
  std::vector<double> inflow(openings, 0.0);
  std::size_t local = 0;
  for_each_boundary_face(piece_, [&](std::span<const NodeId> v, int) {
    const std::size_t whole = face_index.empty() ? local : face_index[local];
    ++local;
    const int k = opening[whole];
    if (k >= 0) inflow[static_cast<std::size_t>(k)] -= ns::face_flux(piece_, f.velocity, v);
  });
  MPI_Allreduce(MPI_IN_PLACE, inflow.data(), static_cast<int>(openings), MPI_DOUBLE, MPI_SUM,
                PETSC_COMM_WORLD);
  return inflow;
}

ns::Reactions PieceSolves::reaction_forces(const ns::FlowField& f, double reynolds) const {
  ns::FlowProblem problem = problem_;
  problem.reynolds = reynolds;
  return ns::reaction_forces(piece_, numbering_, f, problem,
                             ns::airflow_patch_kinds(piece_, driven_), PETSC_COMM_WORLD);
}

std::vector<stability::Mode> PieceSolves::leading_modes(const ns::FlowField& f, double reynolds,
                                                        int modes) const {
  ns::FlowProblem problem = problem_;
  problem.reynolds = reynolds;
  return stability::leading_modes(piece_, numbering_, problem, f, {.modes = modes});
}

Eigen::Vector3d PieceSolves::momentum_outflow(const ns::FlowField& f) const {
  Eigen::Vector3d flux = ns::patch_momentum_flux(piece_, f.velocity, inlet_) +
                         ns::patch_momentum_flux(piece_, f.velocity, outlet_);
  MPI_Allreduce(MPI_IN_PLACE, flux.data(), 3, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  return flux;
}

void write_residual_history(const std::vector<continuation::ContinuationStep>& steps,
                            const std::filesystem::path& path) {
  CsvTable table({"step", "reynolds", "converged", "iteration", "residual"});
  for (std::size_t s = 0; s < steps.size(); ++s)
    for (std::size_t i = 0; i < steps[s].residuals.size(); ++i)
      table.add_row({std::to_string(s), fmt::format("{:g}", steps[s].reynolds),
                     steps[s].converged ? "1" : "0", std::to_string(i),
                     fmt::format("{:.6e}", steps[s].residuals[i])});
  table.write(path);
}

}  // namespace naris::airflow
