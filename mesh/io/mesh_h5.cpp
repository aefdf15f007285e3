#include "mesh/io/mesh_h5.h"

#include <fmt/format.h>

#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5_table.h"

namespace naris {
namespace fs = std::filesystem;

namespace {

constexpr int kFormatVersion = 1;

void write_xdmf(const HybridMesh& mesh, const fs::path& h5_path) {
  const std::string h5 = h5_path.filename().string();
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n";
  auto geometry = [&] {
    x << "   <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"" << mesh.nodes.size()
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << h5
      << ":/nodes</DataItem></Geometry>\n";
  };
  auto grid = [&](const char* name, const char* topology, std::size_t count, int per,
                  const char* dataset, const char* patch_dataset) {
    if (count == 0) return;
    x << "  <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n"
      << "   <Topology TopologyType=\"" << topology << "\" NumberOfElements=\"" << count
      << "\"><DataItem Dimensions=\"" << count << " " << per
      << "\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << h5 << ":" << dataset
      << "</DataItem></Topology>\n";
    geometry();
    if (patch_dataset)
      x << "   <Attribute Name=\"patch\" AttributeType=\"Scalar\" Center=\"Cell\"><DataItem "
        << "Dimensions=\"" << count << "\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << h5
        << ":" << patch_dataset << "</DataItem></Attribute>\n";
    x << "  </Grid>\n";
  };
  x << " <Grid Name=\"mesh\" GridType=\"Collection\" CollectionType=\"Spatial\">\n";
  grid("tetrahedra", "Tetrahedron", mesh.tets.size(), 4, "/cells/tet", nullptr);
  grid("pyramids", "Pyramid", mesh.pyramids.size(), 5, "/cells/pyramid", nullptr);
  grid("hexahedra", "Hexahedron", mesh.hexes.size(), 8, "/cells/hex", nullptr);
  x << " </Grid>\n <Grid Name=\"boundary\" GridType=\"Collection\" CollectionType=\"Spatial\">\n";
  grid("boundary_triangles", "Triangle", mesh.boundary_tris.size(), 3, "/boundary/tri",
       "/boundary/tri_patch");
  grid("boundary_quadrilaterals", "Quadrilateral", mesh.boundary_quads.size(), 4, "/boundary/quad",
       "/boundary/quad_patch");
  x << " </Grid>\n </Domain>\n</Xdmf>\n";

  const fs::path xdmf = fs::path(h5_path).replace_extension(".xdmf");
  write_text_file(xdmf, x.str());
}

}  // namespace

void write_mesh_h5(const HybridMesh& mesh, const fs::path& path) {
  SilenceHdf5 quiet;
  {
    AtomicOutput out(path);
    H5Handle file = create_file(out.temp_path(), path, "naris-mesh", kFormatVersion);
    write_string_attribute(file.get(), "units", "mm", path);
    std::string names;
    for (const auto& n : mesh.patch_names) names += (names.empty() ? "" : "\n") + n;
    write_string_attribute(file.get(), "patch_names", names, path);

    write_table(file.get(), "nodes", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, mesh.nodes.data(),
                mesh.nodes.size(), 3, path);
    H5Handle cells = make_group(file.get(), "cells", path);
    write_table(cells.get(), "tet", H5T_NATIVE_INT32, H5T_STD_I32LE, mesh.tets.data(),
                mesh.tets.size(), 4, path);
    write_table(cells.get(), "pyramid", H5T_NATIVE_INT32, H5T_STD_I32LE, mesh.pyramids.data(),
                mesh.pyramids.size(), 5, path);
    write_table(cells.get(), "hex", H5T_NATIVE_INT32, H5T_STD_I32LE, mesh.hexes.data(),
                mesh.hexes.size(), 8, path);
    H5Handle boundary = make_group(file.get(), "boundary", path);
    write_table(boundary.get(), "tri", H5T_NATIVE_INT32, H5T_STD_I32LE, mesh.boundary_tris.data(),
                mesh.boundary_tris.size(), 3, path);
    write_table(boundary.get(), "tri_patch", H5T_NATIVE_INT32, H5T_STD_I32LE,
                mesh.boundary_tri_patch.data(), mesh.boundary_tri_patch.size(), 1, path);
    write_table(boundary.get(), "quad", H5T_NATIVE_INT32, H5T_STD_I32LE, mesh.boundary_quads.data(),
                mesh.boundary_quads.size(), 4, path);
    write_table(boundary.get(), "quad_patch", H5T_NATIVE_INT32, H5T_STD_I32LE,
                mesh.boundary_quad_patch.data(), mesh.boundary_quad_patch.size(), 1, path);
    cells.reset();
    boundary.reset();
    check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), path, "flush");
    file.reset();
    out.commit();
  }
  write_xdmf(mesh, path);
}

std::string read_mesh_units(const fs::path& path) {
  SilenceHdf5 quiet;
  const H5Handle file = open_file(path, "naris-mesh", kFormatVersion, "a naris mesh file");
  return read_string_attribute(file.get(), "units", path, "a naris mesh file");
}

HybridMesh read_mesh_h5(const fs::path& path) {
  SilenceHdf5 quiet;
  const H5Handle file = open_file(path, "naris-mesh", kFormatVersion, "a naris mesh file");
  if (const std::string units =
          read_string_attribute(file.get(), "units", path, "a naris mesh file");
      units != "mm")
    fail("{}: coordinates in '{}'; naris meshes are in mm", path.string(), units);
  HybridMesh mesh;
  std::istringstream names(
      read_string_attribute(file.get(), "patch_names", path, "a naris mesh file"));
  for (std::string line; std::getline(names, line);) mesh.patch_names.push_back(line);
  read_table(file.get(), "nodes", H5T_NATIVE_DOUBLE, 3, mesh.nodes, path);
  read_table(file.get(), "cells/tet", H5T_NATIVE_INT32, 4, mesh.tets, path);
  read_table(file.get(), "cells/pyramid", H5T_NATIVE_INT32, 5, mesh.pyramids, path);
  read_table(file.get(), "cells/hex", H5T_NATIVE_INT32, 8, mesh.hexes, path);
  read_table(file.get(), "boundary/tri", H5T_NATIVE_INT32, 3, mesh.boundary_tris, path);
  read_table(file.get(), "boundary/tri_patch", H5T_NATIVE_INT32, 1, mesh.boundary_tri_patch, path);
  read_table(file.get(), "boundary/quad", H5T_NATIVE_INT32, 4, mesh.boundary_quads, path);
  read_table(file.get(), "boundary/quad_patch", H5T_NATIVE_INT32, 1, mesh.boundary_quad_patch,
             path);
  const auto n = static_cast<NodeId>(mesh.nodes.size());
  auto check_ids = [&](const auto& cells, const char* what) {
    for (const auto& c : cells)
      for (NodeId id : c)
        if (id < 0 || id >= n) fail("{}: {} refer to node {} of {}", path.string(), what, id, n);
  };
  check_ids(mesh.tets, "tetrahedra");
  check_ids(mesh.pyramids, "pyramids");
  check_ids(mesh.hexes, "hexahedra");
  check_ids(mesh.boundary_tris, "boundary triangles");
  check_ids(mesh.boundary_quads, "boundary quadrilaterals");
  if (mesh.boundary_tri_patch.size() != mesh.boundary_tris.size() ||
      mesh.boundary_quad_patch.size() != mesh.boundary_quads.size())
    fail("{}: boundary patch ids do not match the boundary faces", path.string());
  for (auto p : mesh.boundary_tri_patch)
    if (p < 0 || p >= static_cast<int>(mesh.patch_names.size()))
      fail("{}: boundary patch id {} has no name", path.string(), p);
  for (auto p : mesh.boundary_quad_patch)
    if (p < 0 || p >= static_cast<int>(mesh.patch_names.size()))
      fail("{}: boundary patch id {} has no name", path.string(), p);
  return mesh;
}

}  // namespace naris
