// `naris interpolate`: new slices between the acquired ones (dissertation ch. 2).
#include <memory>

#include "app/commands.h"
#include "app/stage_settings.h"
#include "core/log.h"

namespace naris::app {

void add_interpolate_command(CLI::App& app) {
  auto [o, cmd] = add_stage<InterpolateSettings>(
      app, "interpolate",
      "Insert slices between the acquired slices of a volume along its thick axis by "
      "hierarchical spline-based registration (HSR), or linear / shape-based interpolation; "
      "gray values stay HU (int16 NRRD), 0/1 masks stay labelmaps");
  add_volume_input(cmd, o->job.input, "volume");
  o->table.add_to(cmd);
  cmd->add_option("-o,--output", o->job.output, "interpolated volume (NRRD)")
      ->capture_default_str();
  cmd->callback([o = o] {
    const InterpolateJob job = o->resolve();
    const InterpolateJobResult r = run_interpolate_job(job);
    log_line(format_interpolate_summary(job, r));
  });
}

}  // namespace naris::app
