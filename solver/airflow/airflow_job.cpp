#include "solver/airflow/airflow_job.h"

#include <fmt/format.h>
#include <petscsys.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/units.h"
#include "mesh/io/mesh_h5.h"
#include "mesh/patches/patches.h"
#include "mesh/quality/check.h"
#include "mesh/refine/subdivide.h"
#include "solver/airflow/airflow_outputs.h"
#include "solver/airflow/piece_solves.h"
#include "solver/airflow/solution_file.h"
#include "solver/ns/distributed_field.h"
#include "solver/ns/inlet_expression.h"
#include "solver/parallel/partition.h"

namespace naris::airflow {
namespace fs = std::filesystem;

namespace {

void check_job(const AirflowJob& job) {
  if (!(job.reynolds > 0.0) || !std::isfinite(job.reynolds))
    fail("the Reynolds number must be positive and finite (got {})", job.reynolds);
  if (job.inlet_speed && (!(*job.inlet_speed > 0.0) || !std::isfinite(*job.inlet_speed)))
    fail("the inlet speed must be positive and finite (got {} m/s)", *job.inlet_speed);
  if (!(job.viscosity > 0.0) || !std::isfinite(job.viscosity))
    fail("the viscosity must be positive and finite (got {} m²/s)", job.viscosity);
  if (!(job.density > 0.0) || !std::isfinite(job.density))
    fail("the density must be positive and finite (got {} kg/m³)", job.density);
  if (!(job.start_reynolds > 0.0)) fail("the starting Reynolds number must be positive");
  // A typo in the expression is an input error: caught here, before any output.
  if (job.profile == ns::InletProfile::expression) (void)ns::InletExpression(job.inlet_expression);
  if (job.drive == ns::DrivenPatch::outlet && job.profile == ns::InletProfile::expression)
    fail(
        "an inlet expression shapes the inflow; driven at the outlet the inlet is open (give "
        "uniform or developed, the outflow's shape)");
}

// The mesh as read and checked, and what the problem takes from it.
struct AirflowMesh {
  HybridMesh mesh;
  std::uint64_t fingerprint = 0;
  int inlet = -1, outlet = -1;
  ns::DirichletConditions conditions;  // on the whole mesh, in units of U_in
  PatchOpenings openings;              // of the inlet, in mm
};

// Reads and checks the mesh; its inlet gives d_in and with it U_in and Re (into r).
AirflowMesh read_airflow_mesh(const AirflowJob& job, AirflowResult& r) {
  AirflowMesh m;
  m.mesh = read_mesh_h5(job.mesh);
  const HybridMesh& mesh = m.mesh;
  m.fingerprint = mesh_fingerprint(mesh);
  r.cells = mesh.cell_count();
  r.nodes = mesh.nodes.size();
  m.inlet = mesh.patch_id("inlet");
  m.outlet = mesh.patch_id("outlet");
  if (m.inlet < 0 || m.outlet < 0)
    fail("{}: the mesh has no '{}' patch; mesh it with --inlet and --outlet", job.mesh.string(),
         m.inlet < 0 ? "inlet" : "outlet");
  // Every rank checks the whole mesh: one thread each under MPI, so the ranks share the cores.
  int ranks = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  const MeshCheck check = check_mesh(mesh, ranks > 1 ? 1 : 0);
  if (check.nonpositive_cells)
    fail("{}: {} inverted or flat cells (smallest volume {:.3g} mm³); remesh it with naris mesh",
         job.mesh.string(), check.nonpositive_cells, check.min_volume);
  if (!check.valid())
    fail("{}: the mesh is not valid ({}); remesh it with naris mesh", job.mesh.string(),
         check.describe());
  double outlet_area = 0.0;
  for (const auto& p : patch_report(mesh)) {
    if (p.name == "inlet") {
      r.inlet_area_mm2 = p.area;
      r.inlet_perimeter_mm = p.perimeter;
      r.d_in_mm = p.hydraulic_diameter();
    }
    if (p.name == "outlet") outlet_area = p.area;
  }
  if (!(r.d_in_mm > 0.0)) fail("{}: the inlet patch has no area", job.mesh.string());
  if (!(outlet_area > 0.0)) fail("{}: the outlet patch has no area", job.mesh.string());
  m.openings = patch_openings(mesh, m.inlet);
  const double d_in = r.d_in_mm * kMm;
  r.u_in = job.inlet_speed ? *job.inlet_speed : job.reynolds * job.viscosity / d_in;
  r.reynolds = r.u_in * d_in / job.viscosity;
  // The inlet velocity (mean 1 in units of U_in) from the geometry in mm, where a user's
  // expression is written.
  ns::ProfileShape shape;
  std::optional<ns::InletExpression> expression;
  if (job.profile == ns::InletProfile::expression) {
    expression.emplace(job.inlet_expression);
    shape = [&](const Eigen::Vector3d& x, double distance) { return (*expression)(x, distance); };
  }
  // Driven at the outlet, the same flux leaves there: its mean speed is A_in / A_out.
  const double mean_speed =
      job.drive == ns::DrivenPatch::outlet ? r.inlet_area_mm2 / outlet_area : 1.0;
  m.conditions = ns::airflow_conditions(mesh, job.profile, mean_speed, nullptr, shape, job.drive);
  return m;
}

// A solution on the mesh `coarse_file` prolonged onto the mesh of `fingerprint`, which must be
// that mesh subdivided one to three times.
void prolong_solution(SolutionState& s, const fs::path& restart, const fs::path& coarse_file,
                      const fs::path& mesh_file, std::uint64_t fingerprint, std::size_t nodes) {
  HybridMesh coarse = read_mesh_h5(coarse_file);
  if (mesh_fingerprint(coarse) != s.mesh_fingerprint)
    fail("{}: the checkpoint belongs to another mesh than {}", restart.string(),
         coarse_file.string());
  std::vector<Prolongation> levels;
  while (coarse.nodes.size() < nodes && levels.size() < 3) {
    levels.emplace_back();
    coarse = subdivide(coarse, &levels.back());
  }
  if (mesh_fingerprint(coarse) != fingerprint)
    fail(
        "{} is not {} subdivided: mesh both from the same image and settings, the finer with "
        "--subdivide",
        mesh_file.string(), coarse_file.string());
  for (const Prolongation& p : levels) {
    s.field.velocity = p.apply(s.field.velocity);
    s.field.pressure = p.apply(s.field.pressure);
  }
  s.mesh_fingerprint = fingerprint;
  s.continuation = {};  // the coarse mesh's path does not carry over
}

// The checkpoint to resume from, checked against this mesh and target (r.restarted_from).
std::optional<SolutionState> read_restart(const AirflowJob& job, const AirflowMesh& m,
                                          AirflowResult& r) {
  if (!job.restart) return std::nullopt;
  SolutionState resume = read_solution_h5(*job.restart);
  if (job.restart_mesh)
    prolong_solution(resume, *job.restart, *job.restart_mesh, job.mesh, m.fingerprint, r.nodes);
  if (resume.mesh_fingerprint != m.fingerprint || resume.field.pressure.size() != r.nodes)
    fail("{}: the checkpoint belongs to another mesh than {} ({} nodes vs {})",
         job.restart->string(), job.mesh.string(), resume.field.pressure.size(), r.nodes);
  if (std::abs(resume.d_in_mm - r.d_in_mm) > 1e-9 * r.d_in_mm)
    fail("{}: the checkpoint was scaled with d_in {} mm, this mesh has {} mm",
         job.restart->string(), resume.d_in_mm, r.d_in_mm);
  r.restarted_from = resume.reynolds;
  const bool at_target = job.restart_mesh && resume.reynolds == r.reynolds;
  if (resume.reynolds >= r.reynolds && !at_target)
    fail("{}: the checkpoint is at Re {:.1f}, at or past the target {:.1f}: nothing to continue",
         job.restart->string(), resume.reynolds, r.reynolds);
  return resume;
}

continuation::ContinuationSettings continuation_settings(const AirflowJob& job, double target) {
  continuation::ContinuationSettings s;
  s.target = target;
  s.start = job.start_reynolds;
  s.max_steps = job.max_steps;
  s.step_tolerance = job.step_tolerance;
  s.arclength_steps = job.arclength_steps;
  s.nonlinear = job.nonlinear;
  s.checkpoint = (job.output / "checkpoint.h5").string();
  s.branch = (job.output / "branch.csv").string();
  return s;
}

}  // namespace

// Prepare (the mesh, its scales and conditions, the restart; the pieces under MPI), then the
// Reynolds continuation, then the outputs in SI.
AirflowResult run_airflow_job(const AirflowJob& job) {
  check_job(job);
  Stopwatch total;
  AirflowResult r;
  AirflowMesh m = read_airflow_mesh(job, r);
  std::optional<SolutionState> resume = read_restart(job, m, r);
  // Every input is checked: only now does the job touch the output folder.
  ensure_writable_folder(job.output);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  log_line(fmt::format("naris solve: {} ({} cells), Re {:.1f} on d_in {:.3f} mm, U_in {:.4f} m/s",
                       job.mesh.string(), r.cells, r.reynolds, r.d_in_mm, r.u_in));

  // Nondimensional geometry (lengths in units of d_in), shared among the ranks.
  for (auto& x : m.mesh.nodes) x /= r.d_in_mm;
  Partition part = partition(std::move(m.mesh), rank, ranks);
  ns::FlowProblem problem;
  problem.reynolds = r.reynolds;
  problem.conditions = ns::local_conditions(m.conditions, part.piece.numbering);
  // The natural patch's backflow term: on an outlet it stabilizes; on an inlet open to still
  // air, β = ½ gives its static pressure −½ (u·n)², zero total pressure (flow_problem.h).
  if (job.drive == ns::DrivenPatch::inlet)
    problem.backflow.patches = {{m.outlet, 1.0}};
  else
    problem.backflow.patches = {{m.inlet, 0.5}};
  problem.backflow.smoothing = job.backflow_smoothing;
  // What every solution file of the run carries besides its field and Re.
  SolutionState scales{.target_reynolds = r.reynolds,
                       .u_in = r.u_in,
                       .d_in_mm = r.d_in_mm,
                       .density = job.density,
                       .viscosity = job.viscosity,
                       .mesh_fingerprint = m.fingerprint};
  PieceSolves solves(
      part.piece.mesh, part.piece.numbering, std::move(problem), m.inlet, m.outlet, job.drive,
      scales,
      {job.output / "checkpoint.h5", job.output / "branch.csv", job.output / "residuals.csv"});

  continuation::ReynoldsContinuation continuation(continuation_settings(job, r.reynolds), solves);
  if (resume) {
    ns::FlowField start = ns::local_field(resume->field, part.piece.numbering);
    if (resume->continuation.earlier_reynolds > 0.0)
      resume->continuation.earlier =
          ns::local_field(resume->continuation.earlier, part.piece.numbering);
    continuation.resume(std::move(start), resume->reynolds, std::move(resume->continuation));
    if (job.restart_mesh)
      log_line(fmt::format("  the solution at Re {:.1f} on {} prolonged onto this mesh",
                           resume->reynolds, job.restart_mesh->string()));
    log_line(fmt::format("  restarting from Re {:.1f} ({}), next Re {:.1f}", resume->reynolds,
                         job.restart->string(), continuation.next_reynolds()));
  }
  continuation.run();
  r.steps = continuation.steps();
  if (job.stability_modes > 0) {
    Stopwatch clock;
    // run() reached the target or threw.
    r.modes = solves.leading_modes(continuation.solution(), r.reynolds, job.stability_modes);
    log_line(fmt::format("  stability: {} eigenvalues nearest 0 at Re {:.2f} in {:.1f} s",
                         r.modes.size(), r.reynolds, clock.seconds()));
  }
  write_airflow_outputs(job, part, solves, continuation.solution(), m.openings, r);
  r.seconds = total.seconds();
  if (rank == 0) write_summary_json(job, r);
  return r;
}

}  // namespace naris::airflow
