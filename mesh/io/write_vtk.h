#pragma once
// ParaView files of a hybrid mesh: the volume as .vtu (appended raw binary), the boundary as .vtp
// with a `patch` cell array, and the boundary surface as binary STL.
#include <filesystem>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"

class vtkPolyData;

namespace naris {

// `components` values per node or per cell, one after the other.
struct FieldArray {
  int components = 1;
  std::vector<double> values;
};
using FieldArrays = std::map<std::string, FieldArray>;
// Cell arrays are given in the writer's cell order: tets, then pyramids, then hexes.
using CellFields = FieldArrays;
using PointFields = FieldArrays;

void write_vtu(const HybridMesh& mesh, const std::filesystem::path& path,
               const CellFields& cell_fields = {}, const PointFields& point_fields = {});
// One piece of a parallel VTK file (.pvtu): the cells whose nodes satisfy owned(nodes), with
// the fields restricted to them, written as <stem>_<piece>.vtu beside `path`; piece 0 also
// writes the .pvtu index naming all `pieces`. Fields are given on the whole mesh, as for
// write_vtu. Each piece is written by its own rank, in parallel.
using CellPredicate = std::function<bool(std::span<const NodeId>)>;
void write_pvtu_piece(const HybridMesh& mesh, const std::filesystem::path& path, int piece,
                      int pieces, const CellPredicate& owned, const CellFields& cell_fields = {},
                      const PointFields& point_fields = {});
std::filesystem::path pvtu_piece_path(const std::filesystem::path& path, int piece);
// Face fields are given per boundary face: triangles, then quadrilaterals.
void write_boundary_vtp(const HybridMesh& mesh, const std::filesystem::path& path,
                        const PointFields& face_fields = {});
void write_stl(const HybridMesh& mesh, const std::filesystem::path& path);
// Any polygonal dataset as .vtp (appended, zlib-compressed), written atomically.
void write_vtp(vtkPolyData* data, const std::filesystem::path& path);

}  // namespace naris
