// `naris solve`: the steady airflow in a mesh at a target Reynolds number (dissertation 4.2.4).
#include <fmt/format.h>

#include <memory>

#include "app/commands.h"
#include "app/stage_settings.h"
#include "core/log.h"
#include "solver/parallel/petsc.h"

namespace naris::app {

// PETSc options given with the stage's `petsc` setting, into PETSc's database.
void insert_petsc_options(const std::string& options) {
  if (options.empty()) return;
  petsc::check(PetscOptionsInsertString(nullptr, options.c_str()), "PetscOptionsInsertString");
  // PETSc starts its event log at initialization only when -log_view is already set
  // (PETSC_OPTIONS); given here, the log is begun now so PetscFinalize has one to print.
  PetscBool log_view = PETSC_FALSE;
  petsc::check(PetscOptionsHasName(nullptr, nullptr, "-log_view", &log_view),
               "PetscOptionsHasName");
  if (log_view) petsc::check(PetscLogDefaultBegin(), "PetscLogDefaultBegin");
}

std::string solve_and_summarize(const airflow::AirflowJob& job) {
  std::string summary = airflow::format_airflow_summary(job, airflow::run_airflow_job(job));
  for (const std::string& option : petsc::unused_options())
    summary += fmt::format(
        "\n  warning   PETSc option {} was never used (misspelt, or for a solver this run did "
        "not set up)",
        option);
  return summary;
}

void add_solve_command(CLI::App& app) {
  auto [o, cmd] = add_stage<SolveSettings>(
      app, "solve",
      "Solve the steady incompressible airflow in a mesh made by naris mesh (patches inlet, "
      "outlet, wall): uniform, developed or expression inlet velocity and a traction-free "
      "outlet, or (--drive outlet) the flow drawn out of the outlet with the inlet open to still "
      "air; no-slip walls, Reynolds-number continuation to the target; writes solution.h5 (+ "
      ".xdmf), "
      "solution.vtu (under MPI solution.pvtu with a piece per rank), boundary.vtp, summary.json, "
      "residuals.csv and checkpoint.h5 into -o");
  cmd->add_option("mesh", o->job.mesh, "mesh.h5 written by naris mesh")->required();
  o->table.add_to(cmd);
  cmd->add_option("-o,--output", o->job.output, "output folder")->capture_default_str();
  cmd->callback([o = o] {
    const airflow::AirflowJob job = o->resolve();
    petsc::Session session;
    // Under mpirun every rank runs the job and shares the solves; the first one speaks.
    if (session.rank() > 0) set_verbosity(Verbosity::quiet);
    insert_petsc_options(o->petsc);
    if (session.size() > 1) log_line(fmt::format("naris solve: {} MPI ranks", session.size()));
    log_line(solve_and_summarize(job));
  });
}

}  // namespace naris::app
