#pragma once
// Node relocation (issue 30, item 2): after the collapses of 3.3, the nodes of tetrahedra and
// pyramids below the quality targets move to raise the worst cell around them. Interior nodes
// move freely, wall nodes slide on the wall's level set (they stay on the surface the mesher put
// them on), nodes of flat patches (cut planes) move in their plane and along its line with the
// wall; nodes used by hexahedra only and of other lines between patches stay. A move is
// kept only if it raises the worst score of the node's cells, so no cell is inverted and the
// worst quality never falls.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "mesh/quality/level_set.h"

namespace naris {

struct RelocateOptions {
  // The targets. A cell's score is the smallest of min dihedral / min_dihedral (tetrahedra),
  // scaled Jacobian / min_scaled_jacobian and max_edge_ratio / edge ratio: 1 meets them all.
  double min_dihedral = 12.0;  // degrees
  double min_scaled_jacobian = 0.1;
  double max_edge_ratio = 10.0;
  int sweeps = 6;  // passes over the nodes of cells still below target
};

struct RelocateStats {
  std::size_t cells_below_before = 0;  // tetrahedra and pyramids with score < 1
  std::size_t cells_below_after = 0;
  std::size_t nodes_moved = 0;  // distinct nodes
  std::size_t moves = 0;
  std::size_t rim_slides = 0;  // rim nodes moved along the rim (where the wall's field is flat)
  std::size_t slivers_removed = 0;  // wall tetrahedra that no move could lift
  std::size_t edges_removed = 0;    // interior edges of cells below target, removed by flips
  double worst_before = 0.0;        // lowest score
  double worst_after = 0.0;
  double largest_surface_offset = 0.0;  // mm: |level set| / |gradient| at moved wall nodes
  double seconds = 0.0;
};

// on_surface[p]: the faces of patch p lie on `wall` (the wall and the regions cut from it); their
// nodes slide on it. Nodes of another patch that is flat (a cut plane, a box side: nine tenths of
// its nodes on one plane) move within its plane, and those on its line with the wall along that
// line; its nodes off the plane stay. Without `wall` the wall's nodes stay. unchanged_from (as
// improve_mesh gives it, one entry per cell in the mesh's order) gets −1 for every cell that moved.
RelocateStats relocate_nodes(HybridMesh& mesh, const LevelSet* wall,
                             const std::vector<bool>& on_surface, const RelocateOptions& options,
                             std::vector<std::int64_t>* unchanged_from = nullptr);

}  // namespace naris
