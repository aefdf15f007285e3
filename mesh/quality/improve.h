#pragma once
// Mesh quality improvement (dissertation 3.3): short edges of the tetrahedra and pyramids are
// collapsed to their midpoints (a tiny boundary polygon disappears edge by edge), with the
// pyramid rules of 3.3: a collapsed base edge turns the pyramid into a tetrahedron; a lateral
// edge goes only once its pyramid is split into two tetrahedra, with what lies across its base (a
// pyramid or a boundary quadrilateral; never where a hexahedron does). A boundary node merging
// into a lattice vertex moves the vertex onto the boundary (its hexahedra warp); other hexahedra
// are never touched. A collapse is made only if it keeps the mesh a conforming, watertight
// manifold and every changed cell positive.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris {

struct ImproveOptions {
  // Edges shorter than this fraction of the smallest voxel spacing are collapsed.
  double min_edge_fraction = 0.2;
  // A collapse is refused if a changed cell would fall below this scaled Jacobian.
  double min_scaled_jacobian = 0.02;
};

struct ImproveStats {
  std::size_t short_edges = 0;  // candidates found
  std::size_t collapsed = 0;
  std::size_t refused_topology = 0;  // link condition, pinch, lateral pyramid edge, hex
  std::size_t refused_geometry = 0;  // would invert or flatten a cell or fold the boundary
  std::size_t removed_cells = 0;
  std::size_t pyramids_to_tets = 0;
  std::size_t pyramids_split = 0;   // into two tetrahedra, for a collapse of a lateral edge
  std::size_t vertices_warped = 0;  // lattice vertices moved onto the boundary by a collapse
  double seconds = 0.0;
};

// With unchanged_from: for each cell of the improved mesh (in its order), the index of the same
// cell, in the same place, in the input mesh (its cell order), or −1 for a changed cell.
ImproveStats improve_mesh(HybridMesh& mesh, double voxel_size, const ImproveOptions& options,
                          std::vector<std::int64_t>* unchanged_from = nullptr);

}  // namespace naris
