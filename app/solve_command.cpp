// `naris solve`: the steady airflow in a mesh at a target Reynolds number (dissertation 4.2.4).
#include <fmt/format.h>

#include <memory>

#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "ns/airflow_job.h"
#include "parallel/petsc.h"

namespace naris::app {

void add_solve_command(CLI::App& app) {
  struct Options {
    ns::AirflowJob job;
    std::string profile = "uniform", petsc_options, scheme = "coupled";
    std::filesystem::path restart, restart_mesh;
    bool verbose = false;
    double inlet_speed = 0.0;
  };
  auto o = std::make_shared<Options>();
  ns::AirflowJob& job = o->job;
  // Pseudo-time on by default: on the neonatal airway Newton alone stalls near Re 190, where
  // the jet changes branch; on the phantom it costs a step or two per continuation step.
  job.picard.pseudo_cfl = 5.0;
  auto* cmd = app.add_subcommand(
      "solve",
      "Solve the steady incompressible airflow in a mesh made by naris mesh (patches inlet, "
      "outlet, wall): uniform, developed or expression inlet velocity, traction-free outlet, "
      "no-slip walls, "
      "Reynolds-number continuation to the target; writes solution.h5 (+ .xdmf), solution.vtu "
      "(under MPI solution.pvtu with a piece per rank), boundary.vtp, summary.json, residuals.csv "
      "and checkpoint.h5 into -o");
  cmd->add_option("mesh", job.mesh, "mesh.h5 written by naris mesh")->required();
  cmd->add_option("--re", job.reynolds, "target Reynolds number on the inlet's d_in = 4A/P")
      ->capture_default_str();
  cmd->add_option("--inlet-speed", o->inlet_speed,
                  "mean inlet speed (m/s) instead of --re; Re then follows from it");
  auto* profile =
      cmd->add_option("--inlet-profile", o->profile, "uniform or developed (laminar, any shape)")
          ->check(CLI::IsMember({"uniform", "developed"}))
          ->capture_default_str();
  auto* expression =
      cmd->add_option("--inlet-expression", job.inlet_expression,
                      "inlet profile as an expression of x, y, z and r (mm; r from the inlet's "
                      "centroid), e.g. \"1-(r/1.5)^2\"; scaled to the mean inlet speed")
          ->excludes(profile);
  cmd->add_option("--nu", job.viscosity, "kinematic viscosity (m²/s)")->capture_default_str();
  cmd->add_option("--rho", job.density, "density (kg/m³)")->capture_default_str();
  cmd->add_option("--re-start", job.start_reynolds, "first Reynolds number of the continuation")
      ->capture_default_str();
  cmd->add_option("--max-steps", job.max_steps, "continuation steps at most")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  auto* max_iterations =
      cmd->add_option("--max-iterations", job.picard.max_iterations,
                      "nonlinear (Picard or Newton) iterations per continuation step at most")
          ->check(CLI::PositiveNumber)
          ->capture_default_str();
  cmd->add_option("--scheme", o->scheme,
                  "coupled (Picard then Newton, GMRES on ILU), segregated (FiDAP's momentum / "
                  "pressure-correction sweeps on algebraic multigrid; Picard only, 500 "
                  "iterations per step unless --max-iterations) or segregated-gmres (GMRES on "
                  "the whole system preconditioned by one such sweep)")
      ->check(CLI::IsMember({"coupled", "segregated", "segregated-gmres"}))
      ->capture_default_str();
  cmd->add_option("--velocity-relaxation", job.picard.velocity_relaxation,
                  "segregated: momentum under-relaxation α_u")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  cmd->add_option("--pressure-relaxation", job.picard.pressure_relaxation,
                  "segregated: pressure-correction relaxation α_p")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  cmd->add_option("--picard-steps", job.picard.picard_steps,
                  "Picard steps before Newton's method takes over")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("!--no-newton", job.picard.newton,
                "Picard iteration only (linear convergence; stalls at high Re)");
  cmd->add_option("--linear-tolerance", job.picard.linear_tolerance,
                  "each linear solve's residual reduction, at the tightest")
      ->check(CLI::Range(1e-14, 0.5))
      ->capture_default_str();
  cmd->add_option("--linear-tolerance-max", job.picard.loosest_linear_tolerance,
                  "the loosest reduction, where the nonlinear residual falls slowly (Eisenstat–"
                  "Walker; equal to --linear-tolerance: fixed)")
      ->check(CLI::Range(1e-14, 0.5))
      ->capture_default_str();
  cmd->add_option("--tolerance", job.picard.tolerance,
                  "nonlinear residual relative to the load, per step")
      ->capture_default_str();
  cmd->add_option("--step-tolerance", job.step_tolerance,
                  "nonlinear residual of the continuation steps before the target (the target's "
                  "is --tolerance)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--pseudo-cfl", job.picard.pseudo_cfl,
                  "pseudo-transient continuation: first Courant number, grown as the residual "
                  "falls (0: off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--arclength-steps", job.arclength_steps,
                  "where the continuation in Re stalls at a turning point, follow the steady "
                  "branch by pseudo-arclength continuation for at most N points (0: stop there)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("!--rebuild-preconditioner", job.picard.reuse_preconditioner,
                "set the linear solver's preconditioner up anew for every nonlinear step (by "
                "default it is kept while that saves work)");
  cmd->add_option("--relaxation", job.picard.relaxation,
                  "largest step fraction (0, 1]; the step is cut back while the residual grows")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  auto* restart =
      cmd->add_option("--restart", o->restart,
                      "resume the continuation from a checkpoint (the -o folder's checkpoint.h5 is "
                      "rewritten after every converged step)");
  auto* restart_mesh =
      cmd->add_option("--restart-mesh", o->restart_mesh,
                      "the mesh the --restart file belongs to, when the mesh solved is that mesh "
                      "subdivided (naris mesh --subdivide): its field is prolonged onto this one "
                      "and may be at the target Re itself");
  restart_mesh->needs(restart);
  cmd->add_flag("--verbose", o->verbose, "a line per nonlinear (Picard or Newton) step");
  cmd->add_option("--progress", job.picard.progress_seconds,
                  "seconds between progress lines in a long solve: a nonlinear step's line, and "
                  "within a linear solve that runs longer, its residual (0: none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--petsc", o->petsc_options,
                  "PETSc options for the linear solves (prefix ns_), e.g. \"-ns_ksp_monitor\"");
  cmd->add_option("-o,--output", job.output, "output folder")->capture_default_str();
  cmd->callback([o, expression, max_iterations] {
    petsc::Session session;
    // Under mpirun every rank runs the job and shares the solves; the first one speaks.
    if (session.rank() > 0) set_verbosity(Verbosity::quiet);
    if (!o->petsc_options.empty()) {
      petsc::check(PetscOptionsInsertString(nullptr, o->petsc_options.c_str()),
                   "PetscOptionsInsertString");
      // PETSc starts its event log at initialization only when -log_view is already set
      // (PETSC_OPTIONS); given here, the log is begun now so PetscFinalize has one to print.
      PetscBool log_view = PETSC_FALSE;
      petsc::check(PetscOptionsHasName(nullptr, nullptr, "-log_view", &log_view),
                   "PetscOptionsHasName");
      if (log_view) petsc::check(PetscLogDefaultBegin(), "PetscLogDefaultBegin");
    }
    if (o->inlet_speed != 0.0) o->job.inlet_speed = o->inlet_speed;
    if (!o->restart.empty()) o->job.restart = o->restart;
    if (!o->restart_mesh.empty()) o->job.restart_mesh = o->restart_mesh;
    o->job.picard.log_iterations = o->verbose;
    if (o->scheme == "segregated-gmres")
      o->job.picard.scheme = ns::PicardOptions::Scheme::segregated_krylov;
    if (o->scheme == "segregated") {
      o->job.picard.scheme = ns::PicardOptions::Scheme::segregated;
      // Linear convergence, a few percent per sweep: many more steps than Newton's.
      if (max_iterations->count() == 0) o->job.picard.max_iterations = 500;
    }
    o->job.profile = expression->count() > 0     ? ns::InletProfile::expression
                     : o->profile == "developed" ? ns::InletProfile::developed
                                                 : ns::InletProfile::uniform;
    if (session.size() > 1) log_line(fmt::format("naris solve: {} MPI ranks", session.size()));
    const ns::AirflowResult r = ns::run_airflow_job(o->job);
    log_line(ns::format_airflow_summary(o->job, r));
  });
}

}  // namespace naris::app
