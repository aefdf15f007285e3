#pragma once
#include <CLI/CLI.hpp>

namespace naris::app {

void add_phantom_command(CLI::App& app);
void add_interpolate_command(CLI::App& app);
void add_mesh_command(CLI::App& app);
void add_solve_command(CLI::App& app);
void add_eog_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_segment_command(CLI::App& app);

}  // namespace naris::app
