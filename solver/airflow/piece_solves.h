#pragma once
// The discrete problem on this rank's piece of the mesh as the Reynolds continuation sees it:
// each solve shared by the ranks, checkpoints and the branch's points gathered on the first.
#include <filesystem>
#include <string>
#include <vector>

#include "core/csv.h"
#include "solver/airflow/solution_file.h"
#include "solver/continuation/reynolds_continuation.h"
#include "solver/ns/flow_problem.h"
#include "solver/ns/reaction_force.h"
#include "solver/parallel/partition.h"
#include "solver/stability/linear_stability.h"

namespace naris::airflow {

struct RunFiles {
  std::filesystem::path checkpoint, branch, residuals;
};

class PieceSolves final : public continuation::SteadySolves {
 public:
  // `problem` holds the piece's conditions; its Reynolds number is set for each solve.
  // `scales`: what every solution file of the run carries besides its field and Re.
  PieceSolves(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
              ns::FlowProblem problem, int inlet, int outlet, ns::DrivenPatch driven,
              SolutionState scales, RunFiles files);

  ns::FlowField solve(double reynolds, const nonlinear::NonlinearOptions& options,
                      const ns::FlowField* initial,
                      const nonlinear::ArclengthConstraint* constraint,
                      nonlinear::NonlinearReport& report) override;
  double inner_product(const ns::FlowField& a, const ns::FlowField& b) override;
  void checkpoint(double reynolds, const ns::FlowField& field,
                  const continuation::ContinuationState& state) override;
  void branch_point(double reynolds, const ns::FlowField& field, int newton_steps,
                    double arclength) override;
  void giving_up(const std::vector<continuation::ContinuationStep>& steps) override;

  // Nondimensional, collective: the inlet→outlet drop of the area-averaged pressure, the
  // outlet's area-averaged pressure, the largest speed, the flux out through a patch, and the
  // flux in through each opening of the inlet (`opening`: per boundary face of the whole mesh,
  // mesh/patches/patches.h).
  double pressure_drop(const ns::FlowField& f) const;
  double outlet_pressure(const ns::FlowField& f) const;
  double max_speed(const ns::FlowField& f) const;
  double flux_out(const ns::FlowField& f, int patch) const;
  std::vector<double> opening_inflows(const ns::FlowField& f, const std::vector<int>& opening,
                                      std::size_t openings,
                                      const std::vector<std::size_t>& face_index) const;
  // The forces of the fluid at `reynolds` by the consistent method (ns/reaction_force.h), and
  // the momentum the flow carries out through the inlet and the
  // outlet; nondimensional, collective.
  ns::Reactions reaction_forces(const ns::FlowField& f, double reynolds) const;
  Eigen::Vector3d momentum_outflow(const ns::FlowField& f) const;
  // The linearization's `modes` eigenvalues nearest zero at `reynolds` (stability/). Collective.
  std::vector<stability::Mode> leading_modes(const ns::FlowField& f, double reynolds,
                                             int modes) const;
  // The state at `reynolds` on the first rank (the others get an empty field). Collective.
  SolutionState state_at(const ns::FlowField& field, double reynolds) const;
  bool writer() const { return rank_ == 0; }

 private:
  const HybridMesh& piece_;
  const parallel::NodeNumbering& numbering_;
  ns::FlowProblem problem_;
  int inlet_, outlet_;
  ns::DrivenPatch driven_;
  SolutionState scales_;
  RunFiles files_;
  int rank_ = 0;
  CsvTable branch_{{"reynolds", "arclength", "pressure_drop_pa", "max_speed_m_s", "newton_steps"}};
};

// residuals.csv: every nonlinear residual of every step, converged or not.
void write_residual_history(const std::vector<continuation::ContinuationStep>& steps,
                            const std::filesystem::path& path);

}  // namespace naris::airflow
