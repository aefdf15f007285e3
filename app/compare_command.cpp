// `naris compare`: several subjects side by side (dissertation 4.3.1, Figs. 4.12, 4.13).
#include "app/commands.h"
#include "core/log.h"
#include "postproc/compare/compare_job.h"

namespace naris::app {

void add_compare_command(CLI::App& app) {
  auto [o, cmd] = add_stage<compare::CompareJob>(
      app, "compare",
      "Compare subjects: case folders (case.yaml) or results folders, each with its solve and "
      "planes stages (and optionally trace). Writes compare.csv and compare.md (every subject's "
      "numbers), plane-N.png/.svg (the same plane of all subjects on one colour scale) and "
      "area-distance.png (cross-sectional area against the distance from the anterior tip), "
      "report.html and report.md");
  cmd->add_option("subjects", o->inputs, "case or results folders, two or more")->required();
  cmd->add_option("--plane", o->plane, "the plane drawn side by side, numbered as in planes.csv")
      ->capture_default_str();
  cmd->add_option("--profile-step", o->profile_step,
                  "distance (mm) between the sections of the area–distance plot")
      ->capture_default_str();
  cmd->add_flag("!--no-figures", o->figures, "the figures");
  cmd->add_option("-o,--output", o->output, "output folder")->capture_default_str();
  o->version = NARIS_VERSION;
  cmd->callback(
      [o = o] { log_line(compare::format_compare_summary(*o, compare::run_compare_job(*o))); });
}

}  // namespace naris::app
