// `naris interpolate`: new slices between the acquired ones (dissertation ch. 2).
#include <memory>

#include "commands.h"
#include "core/log.h"
#include "pipeline/image_jobs.h"

namespace naris::app {

void add_interpolate_command(CLI::App& app) {
  struct Options {
    InterpolateJob job;
    std::string method = "hsr";
    int insert = -1;
    double spacing = 0.0;
  };
  auto [o, cmd] = add_stage<Options>(
      app, "interpolate",
      "Insert slices between the acquired slices of a volume along its thick axis by "
      "hierarchical spline-based registration (HSR), or linear / shape-based interpolation; "
      "gray values stay HU (int16 NRRD), 0/1 masks stay labelmaps");
  InterpolateJob& job = o->job;
  add_volume_input(cmd, job.input, "volume");
  cmd->add_option("--method", o->method, "hsr, linear or shape")
      ->check(CLI::IsMember({"hsr", "linear", "shape"}))
      ->capture_default_str();
  cmd->add_option("--axis", job.axis, "slice axis: i, j, k, or auto (the coarsest)")
      ->check(CLI::IsMember({"auto", "i", "j", "k"}))
      ->capture_default_str();
  auto* insert = cmd->add_option("--insert", o->insert, "slices to insert between each pair")
                     ->check(CLI::NonNegativeNumber);
  cmd->add_option("--spacing", o->spacing,
                  "target spacing along the axis (mm); default: the finest in-plane spacing")
      ->check(CLI::PositiveNumber)
      ->excludes(insert);
  cmd->add_option("--block", job.hsr.block, "HSR control-grid block size (pixels)")
      ->check(CLI::Range(2, 256))
      ->capture_default_str();
  cmd->add_option("--levels", job.hsr.levels, "HSR pyramid levels")
      ->check(CLI::Range(1, 12))
      ->capture_default_str();
  cmd->add_option("--iterations", job.hsr.iterations, "HSR iterations per level")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--threads", job.threads, "threads over slice pairs (0: every core)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("-o,--output", job.output, "interpolated volume (NRRD)")->capture_default_str();
  cmd->callback([o] {
    o->job.method = parse_slice_method(o->method);
    if (o->insert >= 0) o->job.insert = o->insert;
    if (o->spacing > 0.0) o->job.spacing = o->spacing;
    const InterpolateJobResult r = run_interpolate_job(o->job);
    log_line(format_interpolate_summary(o->job, r));
  });
}

}  // namespace naris::app
