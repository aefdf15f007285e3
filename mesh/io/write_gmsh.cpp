#include "mesh/io/write_gmsh.h"

#include <fmt/format.h>

#include <cstdio>
#include <memory>

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris {

void write_gmsh22(const HybridMesh& mesh, const std::filesystem::path& path) {
  AtomicOutput out(path);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(out.temp_path().c_str(), "w"),
                                                       &std::fclose);
  if (!file) fail("{}: cannot open for writing", path.string());
  fmt::memory_buffer buf;
  auto flush = [&](bool force) {
    if (!force && buf.size() < (1u << 20)) return;
    if (std::fwrite(buf.data(), 1, buf.size(), file.get()) != buf.size())
      fail("{}: write failed (disk full?)", path.string());
    buf.clear();
  };
  const int fluid = static_cast<int>(mesh.patch_names.size()) + 1;
  fmt::format_to(std::back_inserter(buf),
                 "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n{}\n",
                 mesh.patch_names.size() + 1);
  for (std::size_t p = 0; p < mesh.patch_names.size(); ++p)
    fmt::format_to(std::back_inserter(buf), "2 {} \"{}\"\n", p + 1, mesh.patch_names[p]);
  fmt::format_to(std::back_inserter(buf), "3 {} \"fluid\"\n$EndPhysicalNames\n$Nodes\n{}\n", fluid,
                 mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const auto& x = mesh.nodes[n];
    fmt::format_to(std::back_inserter(buf), "{} {} {} {}\n", n + 1, x[0], x[1], x[2]);
    flush(false);
  }
  const std::size_t elements =
      mesh.boundary_tris.size() + mesh.boundary_quads.size() + mesh.cell_count();
  fmt::format_to(std::back_inserter(buf), "$EndNodes\n$Elements\n{}\n", elements);
  std::size_t id = 0;
  auto element = [&](int type, int physical, const auto& nodes) {
    fmt::format_to(std::back_inserter(buf), "{} {} 2 {} {}", ++id, type, physical, physical);
    for (NodeId v : nodes) fmt::format_to(std::back_inserter(buf), " {}", v + 1);
    buf.push_back('\n');
    flush(false);
  };
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f)
    element(2, mesh.boundary_tri_patch[f] + 1, mesh.boundary_tris[f]);
  for (std::size_t f = 0; f < mesh.boundary_quads.size(); ++f)
    element(3, mesh.boundary_quad_patch[f] + 1, mesh.boundary_quads[f]);
  for (const auto& c : mesh.tets) element(4, fluid, c);
  for (const auto& c : mesh.pyramids) element(7, fluid, c);
  for (const auto& c : mesh.hexes) element(5, fluid, c);
  fmt::format_to(std::back_inserter(buf), "$EndElements\n");
  flush(true);
  if (std::fflush(file.get()) != 0) fail("{}: write failed (disk full?)", path.string());
  file.reset();
  out.commit();
}

}  // namespace naris
