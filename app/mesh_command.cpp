#include <cstdio>
#include <memory>

#include "commands.h"
#include "core/log.h"
#include "pipeline/mesh_job.h"

namespace naris::app {

void add_mesh_command(CLI::App& app) {
  // Option storage must outlive this function: the callback runs during parsing.
  struct Options {
    MeshJob job;
    std::string inside = "below";
    bool no_improve = false, all_components = false, no_check = false, no_msh = false;
  };
  auto opt = std::make_shared<Options>();
  MeshJob* const options_job = &opt->job;
  auto* cmd = app.add_subcommand(
      "mesh",
      "Mesh the inside of an image with marching volume elements: hexahedra inside, tetrahedra "
      "at the wall, pyramids between; writes mesh.h5 (+ .xdmf), mesh.vtu, boundary.vtp, "
      "surface.stl, mesh.msh and mesh.json beside -o.");
  add_volume_input(cmd, options_job->input, "image");
  auto* threshold = cmd->add_option("--threshold", options_job->threshold,
                                    "inside is below T (CT air; see --inside)");
  auto* label = cmd->add_option("--label", options_job->label,
                                "inside is the voxels equal to L "
                                "(default for 0/1 labelmaps: 1)");
  threshold->excludes(label);
  cmd->add_option("--inside", opt->inside, "with --threshold: inside is 'below' or 'above' T")
      ->check(CLI::IsMember({"below", "above"}))
      ->capture_default_str();
  cmd->add_option("--inlet", options_job->inlet,
                  "inlet cut plane: voxel index (e.g. j=19) or physical p=x,y,z;n=nx,ny,nz (mm); "
                  "the side towards the object's centre is kept");
  cmd->add_option("--outlet", options_job->outlet, "outlet cut plane, same forms as --inlet");
  cmd->add_option("--patch", options_job->regions,
                  "carve a named patch out of the wall: name:box=x0,y0,z0,x1,y1,z1 or "
                  "name:sphere=x,y,z,r (mm); repeatable");
  cmd->add_flag("--no-improve", opt->no_improve, "skip the quality improvement of section 3.3");
  cmd->add_option("--min-edge", options_job->improve_options.min_edge_fraction,
                  "improvement: collapse edges shorter than this fraction of the voxel size")
      ->check(CLI::Range(0.0, 0.5))
      ->capture_default_str();
  cmd->add_option("--subdivide", options_job->subdivisions,
                  "refine N times after the improvement, each time every cell into 8 of half "
                  "its size filling the same volume (same wall, inlet and outlet; for "
                  "mesh-convergence studies)")
      ->check(CLI::Range(0, 3))
      ->capture_default_str();
  cmd->add_flag("--all-components", opt->all_components,
                "keep every connected component (default: the largest only)");
  cmd->add_flag("--no-check", opt->no_check, "skip the conformity/watertightness check");
  cmd->add_flag("--no-msh", opt->no_msh, "do not write the Gmsh file");
  cmd->add_option("-o,--output", options_job->output,
                  "output mesh file (its folder receives the rest)")
      ->capture_default_str();
  cmd->callback([opt] {
    MeshJob* const job = &opt->job;  // NOLINT: the same job the options fill
    job->inside_above = opt->inside == "above";
    job->improve = !opt->no_improve;
    job->keep_largest = !opt->all_components;
    job->check = !opt->no_check;
    job->write_msh = !opt->no_msh;
    if (job->output.extension() != ".h5") job->output.replace_extension(".h5");
    MeshJobResult result = run_mesh_job(*job);
    write_mesh_outputs(*job, result);
    log_line(format_mesh_summary(*job, result));
  });
}

}  // namespace naris::app
