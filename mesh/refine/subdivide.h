#pragma once
// Uniform refinement of a hybrid mesh that keeps its geometry: every edge is halved, every
// quadrilateral split at its bilinear centre, every hexahedron at its trilinear centre, so each
// cell becomes cells of half its size filling exactly the same volume — a tetrahedron 8
// tetrahedra, a hexahedron 8 hexahedra, a pyramid 6 pyramids and 4 tetrahedra — and every
// boundary face 4 faces of the same patch. Triangles stay planar and quadrilaterals stay on the
// parent's bilinear surface, so the wall, the inlet and the outlet are the same surfaces with
// the same areas and perimeters (hence the same d_in and U_in). That makes it the tool for a
// mesh-convergence study on one anatomy: the geometry does not change with the resolution, as
// it would when the image is sampled more finely.
#include <cstdint>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris {

// The refined mesh's nodes as means of the parent mesh's: node i is the mean of
// parents[offsets[i] .. offsets[i + 1]) — one node (itself), an edge's two, a quadrilateral's
// four or a hexahedron's eight. That mean is the parent's P1/Q1 (and pyramid) interpolant at the
// node, so a nodal field on the parent mesh prolongs to the same function on the refined one.
struct Prolongation {
  std::vector<std::int64_t> offsets;  // refined nodes + 1
  std::vector<NodeId> parents;

  // Values: a random-access container of numbers or Eigen vectors, one per parent node.
  template <class Values, class T = typename Values::value_type>
  std::vector<T> apply(const Values& parent_values) const {
    std::vector<T> out(offsets.size() - 1);
    for (std::size_t i = 0; i + 1 < offsets.size(); ++i) {
      T sum =
          parent_values[static_cast<std::size_t>(parents[static_cast<std::size_t>(offsets[i])])];
      for (auto k = offsets[i] + 1; k < offsets[i + 1]; ++k)
        sum += parent_values[static_cast<std::size_t>(parents[static_cast<std::size_t>(k)])];
      out[i] = sum / static_cast<double>(offsets[i + 1] - offsets[i]);
    }
    return out;
  }
};

// One level of refinement. The refined mesh is conforming when the input is. Nodes are numbered
// after the input's (each new node just after the lowest-numbered node it derives from), so the
// slab-by-slab numbering of the mesher, which the solver's partition and ordering rely on,
// carries over.
HybridMesh subdivide(const HybridMesh& mesh, Prolongation* prolongation = nullptr);

}  // namespace naris
