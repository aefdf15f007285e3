// `naris segment`: airway labelmap from a CT volume (dissertation 4.2.2).
#include <memory>

#include "commands.h"
#include "core/log.h"
#include "pipeline/image_jobs.h"

namespace naris::app {

void add_segment_command(CLI::App& app) {
  struct Options {
    SegmentJob job;
    std::string inside = "below";
    bool all_components = false;
  };
  auto [o, cmd] = add_stage<Options>(
      app, "segment",
      "Segment the airway of a CT volume: threshold (automatic: the HU histogram's valley nearest "
      "−1000), 26-connected region growing from seeds (or every voxel below the threshold), "
      "largest component; writes a labelmap NRRD that 3D Slicer opens");
  SegmentJob& job = o->job;
  add_volume_input(cmd, job.input, "CT volume");
  cmd->add_option("--threshold", job.threshold, "HU threshold, or 'auto'")->capture_default_str();
  cmd->add_option("--inside", o->inside, "the airway is 'below' or 'above' the threshold")
      ->check(CLI::IsMember({"below", "above"}))
      ->capture_default_str();
  cmd->add_option("--seed", job.seeds,
                  "seed voxel i,j,k or point x,y,z mm in the airway; repeatable");
  cmd->add_flag("--all-components", o->all_components,
                "keep every component (default: the largest)");
  cmd->add_option("--rotate", job.rotate,
                  "rotate the volume first, AXIS:DEGREES about image axis i, j or k (e.g. i:30); "
                  "seeds in voxels then refer to the rotated grid, seeds in mm do not change");
  cmd->add_option("--decimate", job.decimate, "average N×N blocks of each slice first")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  cmd->add_option("-o,--output", job.output, "labelmap NRRD")->capture_default_str();
  cmd->callback([o] {
    o->job.inside_above = o->inside == "above";
    o->job.keep_largest = !o->all_components;
    const SegmentJobResult r = run_segment_job(o->job);
    log_line(format_segment_summary(o->job, r));
  });
}

}  // namespace naris::app
