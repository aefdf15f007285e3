#include "io/mesh_h5.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/hdf5_handle.h"

namespace naris {
namespace fs = std::filesystem;

namespace {

constexpr int kFormatVersion = 1;

// HDF5 prints its own error stack by default; naris reports errors itself.
struct SilenceHdf5 {
  H5E_auto2_t func = nullptr;
  void* data = nullptr;
  SilenceHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &func, &data);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~SilenceHdf5() { H5Eset_auto2(H5E_DEFAULT, func, data); }
};

void check(herr_t status, const fs::path& path, const char* what) {
  if (status < 0) fail("{}: HDF5 failed to {}", path.string(), what);
}

H5Handle make_group(hid_t parent, const char* name, const fs::path& path) {
  H5Handle g(H5Gcreate2(parent, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (!g.valid()) fail("{}: cannot create group {}", path.string(), name);
  return g;
}

// A 2D dataset [rows, cols], chunked so that large meshes stream through the library.
void write_table(hid_t parent, const char* name, hid_t mem_type, hid_t file_type, const void* data,
                 hsize_t rows, hsize_t cols, const fs::path& path) {
  const int rank = cols > 1 ? 2 : 1;
  const hsize_t dims[2] = {rows, cols};
  H5Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose);
  H5Handle props(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  if (rows > 0) {
    const hsize_t chunk[2] = {std::min<hsize_t>(rows, 1u << 16), cols};
    check(H5Pset_chunk(props.get(), rank, chunk), path, "set chunking");
  }
  H5Handle set(
      H5Dcreate2(parent, name, file_type, space.get(), H5P_DEFAULT, props.get(), H5P_DEFAULT),
      H5Dclose);
  if (!set.valid()) fail("{}: cannot create dataset {}", path.string(), name);
  if (rows > 0)
    check(H5Dwrite(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), path, "write data");
}

void write_string_attribute(hid_t obj, const char* name, const std::string& value,
                            const fs::path& path) {
  H5Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<std::size_t>(1, value.size()));
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  H5Handle attr(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  check(H5Awrite(attr.get(), type.get(), value.empty() ? " " : value.c_str()), path,
        "write attribute");
}

std::string read_string_attribute(hid_t obj, const char* name, const fs::path& path) {
  if (H5Aexists(obj, name) <= 0)
    fail("{}: not a naris mesh file (no '{}' attribute)", path.string(), name);
  H5Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  H5Handle type(H5Aget_type(attr.get()), H5Tclose);
  std::string value(H5Tget_size(type.get()), '\0');
  check(H5Aread(attr.get(), type.get(), value.data()), path, "read attribute");
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

template <class Array>
void read_table(hid_t file, const char* name, hid_t mem_type, std::size_t cols, Array& out,
                const fs::path& path) {
  H5Handle set(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose);
  if (!set.valid()) fail("{}: missing dataset {}", path.string(), name);
  H5Handle space(H5Dget_space(set.get()), H5Sclose);
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if ((cols > 1 && (rank != 2 || dims[1] != cols)) || (cols == 1 && rank != 1))
    fail("{}: dataset {} has the wrong shape", path.string(), name);
  out.resize(dims[0]);
  if (dims[0] > 0)
    check(H5Dread(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), path,
          "read data");
}

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
  AtomicOutput out(xdmf);
  std::ofstream(out.temp_path()) << x.str();
  out.commit();
}

}  // namespace

void write_mesh_h5(const HybridMesh& mesh, const fs::path& path) {
  SilenceHdf5 quiet;
  {
    AtomicOutput out(path);
    H5Handle file(H5Fcreate(out.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                  H5Fclose);
    if (!file.valid()) fail("{}: cannot create the HDF5 file", path.string());
    write_string_attribute(file.get(), "format", "naris-mesh", path);
    write_string_attribute(file.get(), "units", "mm", path);
    write_string_attribute(file.get(), "version", std::to_string(kFormatVersion), path);
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

HybridMesh read_mesh_h5(const fs::path& path) {
  SilenceHdf5 quiet;
  std::error_code ec;
  if (!fs::exists(path, ec)) fail("{}: no such mesh file", path.string());
  if (H5Fis_hdf5(path.c_str()) <= 0) fail("{}: not an HDF5 file", path.string());
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) fail("{}: cannot open the HDF5 file (corrupt?)", path.string());
  if (read_string_attribute(file.get(), "format", path) != "naris-mesh")
    fail("{}: not a naris mesh file", path.string());
  const std::string version = read_string_attribute(file.get(), "version", path);
  if (version != std::to_string(kFormatVersion))
    fail("{}: mesh format version {} is not supported (this naris reads version {})", path.string(),
         version, kFormatVersion);
  HybridMesh mesh;
  std::istringstream names(read_string_attribute(file.get(), "patch_names", path));
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
