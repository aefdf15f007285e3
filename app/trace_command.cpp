// `naris trace`: particle paths from release points on the naris through a solved flow
// (dissertation 4.3.1), massless tracers or inertial particles with deposition.
#include <fmt/format.h>

#include <memory>

#include "app/commands.h"
#include "app/stage_settings.h"
#include "app/trace_figures.h"
#include "core/log.h"
#include "solver/parallel/petsc.h"

namespace naris::app {

void add_trace_command(CLI::App& app) {
  auto [o, cmd] = add_stage<TraceSettings>(
      app, "trace",
      "Track particles through a flow solved by naris solve: massless tracers (Dormand–Prince "
      "RK45) or inertial particles (drag, slip correction, gravity) that deposit on the wall; "
      "release groups on the naris, a grid, flux-weighted random points, a line or a file; "
      "fates, deposits and crossings of cross-section planes. Writes paths.vtp, deposits.vtp, "
      "particles.csv, crossings.csv, fates.csv, summary.json, paths.png and crossings.png into "
      "-o. Under mpirun the ranks share the particles");
  cmd->add_option("solution", o->job.solution, "solution.h5 written by naris solve")->required();
  o->table.add_to(cmd);
  cmd->add_option("-o,--output", o->job.output, "output folder")->capture_default_str();
  cmd->callback([o = o] {
    const particles::TraceJob job = o->resolve();
    petsc::Session session;
    if (session.rank() > 0) set_verbosity(Verbosity::quiet);
    const particles::TraceResult r = particles::run_trace_job(job);
    if (session.rank() > 0) return;
    if (o->figures) write_trace_figures(r, job.output);
    log_line(particles::format_trace_summary(job, r));
  });
}

}  // namespace naris::app
