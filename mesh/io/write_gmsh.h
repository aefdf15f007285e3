#pragma once
// Gmsh .msh version 2.2 (ASCII): the version OpenFOAM's gmshToFoam and most other solvers read.
// Each boundary patch is a physical surface group named after it; the cells form the physical
// volume group "fluid". Node orders of tet, pyramid and hexahedron match VTK's.
#include <filesystem>

#include "mesh/hybrid_mesh.h"

namespace naris {

void write_gmsh22(const HybridMesh& mesh, const std::filesystem::path& path);

}  // namespace naris
