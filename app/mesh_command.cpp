// `naris mesh`: a conforming hybrid mesh of the inside of an image (dissertation ch. 3).
#include <memory>

#include "app/commands.h"
#include "app/stage_settings.h"
#include "core/log.h"

namespace naris::app {

void add_mesh_command(CLI::App& app) {
  auto [o, cmd] = add_stage<MeshSettings>(
      app, "mesh",
      "Mesh the inside of an image with marching volume elements: hexahedra inside, tetrahedra "
      "at the wall, pyramids between; writes mesh.h5 (+ .xdmf), mesh.vtu, boundary.vtp, "
      "surface.stl, mesh.msh and mesh.json beside -o.");
  add_volume_input(cmd, o->job.input, "image");
  o->table.add_to(cmd);
  cmd->add_option("-o,--output", o->job.output, "output mesh file (its folder receives the rest)")
      ->capture_default_str();
  cmd->callback([o = o] {
    MeshJob job = o->resolve();
    if (job.output.extension() != ".h5") job.output.replace_extension(".h5");
    MeshJobResult result = run_mesh_job(job);
    write_mesh_outputs(job, result);
    log_line(format_mesh_summary(job, result));
  });
}

}  // namespace naris::app
