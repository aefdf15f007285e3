// `naris planes`: cross-sections of a solved flow on planes normal to the anterior–posterior
// axis (dissertation 4.3.1, Table 4.3, Figs. 4.6–4.11).
#include "app/commands.h"
#include "app/stage_settings.h"
#include "core/log.h"

namespace naris::app {

void add_planes_command(CLI::App& app) {
  auto [o, cmd] = add_stage<PlanesSettings>(
      app, "planes",
      "Cut a flow solved by naris solve with cross-section planes: per plane and connected piece "
      "the area, perimeter (smoothed at the voxel scale, and raw), hydraulic diameter, volume "
      "flux, mean and maximum axial velocity, maximum speed and the flux share of named regions; "
      "a figure per plane (speed bands and contours, secondary-velocity arrows). Writes "
      "planes.csv, planes.vtp, summary.json and plane-N.png/.svg into -o");
  cmd->add_option("solution", o->job.solution, "solution.h5 written by naris solve")->required();
  o->table.add_to(cmd);
  cmd->add_option("-o,--output", o->job.output, "output folder")->capture_default_str();
  cmd->callback([o = o] {
    const planes::PlanesJob job = o->resolve();
    log_line(planes::format_planes_summary(job, planes::run_planes_job(job)));
  });
}

}  // namespace naris::app
