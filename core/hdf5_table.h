#pragma once
// The HDF5 building blocks of naris's own files (mesh, solution, checkpoint): 1D/2D tables,
// string attributes, groups, with every failure a naris::Error naming the file.
#include <algorithm>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "core/hdf5_handle.h"

namespace naris {

// HDF5 prints its own error stack by default; naris reports errors itself.
struct SilenceHdf5 {
  H5E_auto2_t func = nullptr;
  void* data = nullptr;
  SilenceHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &func, &data);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~SilenceHdf5() { H5Eset_auto2(H5E_DEFAULT, func, data); }
  SilenceHdf5(const SilenceHdf5&) = delete;
  SilenceHdf5& operator=(const SilenceHdf5&) = delete;
};

void check(herr_t status, const std::filesystem::path& path, const char* what);
// A new file at `temp` (an AtomicOutput's temporary) for `path`, stamped with the attributes
// format and version that open_file checks.
H5Handle create_file(const std::filesystem::path& temp, const std::filesystem::path& path,
                     const std::string& format, int version);
// An existing naris file of the given format and version, read-only; `kind` names it in errors
// ("a naris mesh file").
H5Handle open_file(const std::filesystem::path& path, const std::string& format, int version,
                   const char* kind);
H5Handle make_group(hid_t parent, const char* name, const std::filesystem::path& path);
// A 2D dataset [rows, cols] (1D when cols is 1), chunked so that large arrays stream.
void write_table(hid_t parent, const char* name, hid_t mem_type, hid_t file_type, const void* data,
                 hsize_t rows, hsize_t cols, const std::filesystem::path& path);
void write_string_attribute(hid_t obj, const char* name, const std::string& value,
                            const std::filesystem::path& path);
// `kind` names what the file should be ("a naris mesh file") in the error for a missing one.
std::string read_string_attribute(hid_t obj, const char* name, const std::filesystem::path& path,
                                  const char* kind);

template <class Array>
void read_table(hid_t file, const char* name, hid_t mem_type, std::size_t cols, Array& out,
                const std::filesystem::path& path) {
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

}  // namespace naris
