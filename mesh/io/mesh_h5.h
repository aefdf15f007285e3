#pragma once
// naris's own mesh file, HDF5 (+ an XDMF sidecar so ParaView opens it):
//
//   /nodes                 float64 [N, 3]   coordinates in millimetres
//   /cells/tet             int32   [T, 4]   VTK_TETRA order
//   /cells/pyramid         int32   [P, 5]   VTK_PYRAMID order (base 0-3, apex 4)
//   /cells/hex             int32   [H, 8]   VTK_HEXAHEDRON order
//   /boundary/tri          int32   [B3, 3]  outward boundary triangles
//   /boundary/tri_patch    int32   [B3]
//   /boundary/quad         int32   [B4, 4]  outward boundary quadrilaterals
//   /boundary/quad_patch   int32   [B4]
//   root attributes: format = "naris-mesh", version = 1, units = "mm",
//                    patch_names = newline-separated names, indexed by the patch ids
//
// Node ids are 0-based. Every cell has positive volume.
#include <filesystem>
#include <string>

#include "mesh/hybrid_mesh.h"

namespace naris {

// Writes path and the sidecar path.replace_extension(".xdmf").
void write_mesh_h5(const HybridMesh& mesh, const std::filesystem::path& path);
// Throws naris::Error for a missing or foreign file, or one whose units are not millimetres.
HybridMesh read_mesh_h5(const std::filesystem::path& path);
// The file's `units` attribute alone (naris writes "mm").
std::string read_mesh_units(const std::filesystem::path& path);

}  // namespace naris
