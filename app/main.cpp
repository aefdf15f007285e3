// The `naris` command line: one subcommand per stage. Errors print as
// `naris: error: <what, where, what to do>` with a non-zero exit.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "app/commands.h"
#include "core/error.h"
#include "core/log.h"

int main(int argc, char** argv) {
  CLI::App app{"naris: from a CT scan of a nose to a validated airflow simulation"};
  app.set_version_flag("--version", std::string("naris ") + NARIS_VERSION);
  app.require_subcommand(1);
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "print nothing but errors")->configurable(false);
  app.parse_complete_callback(
      [&] { naris::set_verbosity(quiet ? naris::Verbosity::quiet : naris::Verbosity::normal); });
  naris::app::add_phantom_command(app);
  naris::app::add_interpolate_command(app);
  naris::app::add_segment_command(app);
  naris::app::add_mesh_command(app);
  naris::app::add_solve_command(app);
  naris::app::add_trace_command(app);
  naris::app::add_planes_command(app);
  naris::app::add_compare_command(app);
  naris::app::add_eog_command(app);
  naris::app::add_run_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      std::fprintf(stderr, "naris: error: %s (see 'naris %s--help')\n", e.what(),
                   app.get_subcommands().empty()
                       ? ""
                       : (app.get_subcommands().front()->get_name() + " ").c_str());
      return 2;
    }
    return app.exit(e);
  } catch (const naris::Error& e) {
    std::fprintf(stderr, "naris: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr,
                 "naris: error: out of memory (try cropping the image or a coarser grid)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "naris: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
