// `naris phantom`: the procedural CT of a right nasal cavity, the project's default case.
#include <memory>

#include "app/commands.h"
#include "core/log.h"
#include "mesh/image/image_jobs.h"

namespace naris::app {

void add_phantom_command(CLI::App& app) {
  auto [job, cmd] = add_stage<PhantomJob>(
      app, "phantom",
      "Write a procedural CT scan of a right human nasal cavity (nostril, vestibule, valve, "
      "meatuses between turbinate folds, olfactory slit, nasopharynx): thick coronal slices "
      "with partial volume and noise, in HU; the subject number varies the anatomy");
  cmd->add_option("--subject", job->subject, "subject number (1: the reference anatomy)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--pixel", job->sampling.pixel, "in-plane pixel size (mm)")
      ->check(CLI::Range(0.05, 5.0))
      ->capture_default_str();
  cmd->add_option("--slice", job->sampling.slice, "slice thickness and spacing (mm)")
      ->check(CLI::Range(0.05, 10.0))
      ->capture_default_str();
  cmd->add_option("--noise", job->sampling.noise, "noise standard deviation (HU)")
      ->check(CLI::Range(0.0, 500.0))
      ->capture_default_str();
  cmd->add_option("--exact-mask", job->exact_mask,
                  "also write the exact airway as a labelmap (for measuring accuracy)");
  cmd->add_option("--mask-spacing", job->mask_spacing,
                  "slice spacing of the exact mask (mm; in-plane it follows --pixel)")
      ->check(CLI::Range(0.05, 10.0))
      ->capture_default_str();
  cmd->add_option("-o,--output", job->output, "CT volume (NRRD, int16 HU)")->capture_default_str();
  cmd->callback([job] {
    const PhantomJobResult r = run_phantom_job(*job);
    log_line(format_phantom_summary(*job, r));
  });
}

}  // namespace naris::app
