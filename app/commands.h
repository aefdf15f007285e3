#pragma once
#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include "solver/airflow/airflow_job.h"

namespace naris::app {

// A subcommand whose options live in a shared Options object: CLI11 fills it while parsing and
// the callback, which runs later, still owns it.
template <class Options>
std::pair<std::shared_ptr<Options>, CLI::App*> add_stage(CLI::App& app, const char* name,
                                                         const std::string& description) {
  return {std::make_shared<Options>(), app.add_subcommand(name, description)};
}

// The positional input image of a stage: any format read_volume reads.
inline void add_volume_input(CLI::App* cmd, std::filesystem::path& input, const char* what) {
  cmd->add_option(
         "input", input,
         std::string(what) + " (.nrrd/.nhdr, .nii/.nii.gz, .mha/.mhd, .vti or a DICOM folder)")
      ->required();
}

void add_phantom_command(CLI::App& app);
void add_interpolate_command(CLI::App& app);
void add_mesh_command(CLI::App& app);
void add_solve_command(CLI::App& app);
void add_trace_command(CLI::App& app);
void add_planes_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_eog_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_segment_command(CLI::App& app);

// PETSc options (a `petsc` setting) into PETSc's database; -log_view begins the event log.
void insert_petsc_options(const std::string& options);
// The airflow job run, and its summary followed by one warning per PETSc option that nothing
// read (misspelt, or for a solver the run did not set up): known only once the solve has run.
std::string solve_and_summarize(const airflow::AirflowJob& job);

}  // namespace naris::app
