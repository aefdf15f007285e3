#include "core/hdf5_table.h"

namespace naris {
namespace fs = std::filesystem;

void check(herr_t status, const fs::path& path, const char* what) {
  if (status < 0) fail("{}: HDF5 failed to {}", path.string(), what);
}

H5Handle create_file(const fs::path& temp, const fs::path& path, const std::string& format,
                     int version) {
  H5Handle file(H5Fcreate(temp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) fail("{}: cannot create the HDF5 file", path.string());
  write_string_attribute(file.get(), "format", format, path);
  write_string_attribute(file.get(), "version", std::to_string(version), path);
  return file;
}

H5Handle open_file(const fs::path& path, const std::string& format, int version, const char* kind) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail("{}: no such file (expected {})", path.string(), kind);
  if (H5Fis_hdf5(path.c_str()) <= 0) fail("{}: not an HDF5 file", path.string());
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) fail("{}: cannot open the HDF5 file (corrupt?)", path.string());
  if (read_string_attribute(file.get(), "format", path, kind) != format)
    fail("{}: not {}", path.string(), kind);
  const std::string found = read_string_attribute(file.get(), "version", path, kind);
  if (found != std::to_string(version))
    fail("{}: format version {} is not supported (this naris reads version {})", path.string(),
         found, version);
  return file;
}

H5Handle make_group(hid_t parent, const char* name, const fs::path& path) {
  H5Handle g(H5Gcreate2(parent, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (!g.valid()) fail("{}: cannot create group {}", path.string(), name);
  return g;
}

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

std::string read_string_attribute(hid_t obj, const char* name, const fs::path& path,
                                  const char* kind) {
  if (H5Aexists(obj, name) <= 0) fail("{}: not {} (no '{}' attribute)", path.string(), kind, name);
  H5Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  H5Handle type(H5Aget_type(attr.get()), H5Tclose);
  std::string value(H5Tget_size(type.get()), '\0');
  check(H5Aread(attr.get(), type.get(), value.data()), path, "read attribute");
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

}  // namespace naris
