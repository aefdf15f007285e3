// `naris segment`: airway labelmap from a CT volume (dissertation 4.2.2).
#include <memory>

#include "app/commands.h"
#include "app/stage_settings.h"
#include "core/log.h"

namespace naris::app {

void add_segment_command(CLI::App& app) {
  auto [o, cmd] = add_stage<SegmentSettings>(
      app, "segment",
      "Segment the airway of a CT volume: threshold (automatic: the HU histogram's valley nearest "
      "−1000), 26-connected region growing from seeds (or every voxel below the threshold), "
      "largest component; writes a labelmap NRRD that 3D Slicer opens");
  add_volume_input(cmd, o->job.input, "CT volume");
  o->table.add_to(cmd);
  cmd->add_option("-o,--output", o->job.output, "labelmap NRRD")->capture_default_str();
  cmd->callback([o = o] {
    const SegmentJob job = o->resolve();
    const SegmentJobResult r = run_segment_job(job);
    log_line(format_segment_summary(job, r));
  });
}

}  // namespace naris::app
