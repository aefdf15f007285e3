#pragma once
// Topological and geometric invariants of a hybrid mesh, computed from the cells alone so they
// can judge any mesher: positive volumes, conforming faces (every interior face shared by two
// cells with opposite orientation), boundary faces that are exactly the unshared cell faces
// with outward orientation, a watertight boundary, and the Euler characteristic.
#include <cstddef>
#include <string>

#include "mesh/hybrid_mesh.h"

namespace naris {

struct MeshCheck {
  std::size_t nonpositive_cells = 0;
  std::size_t unmatched_faces = 0;      // cell faces neither shared nor on the boundary list
  std::size_t misoriented_pairs = 0;    // shared faces with the same orientation on both sides
  std::size_t overshared_faces = 0;     // a face used by three or more cells
  std::size_t boundary_mismatches = 0;  // boundary list entries that are not cell faces, or inward
  std::size_t open_boundary_edges = 0;  // boundary edges not on exactly two boundary faces
  std::size_t unused_nodes = 0;
  long euler_cells = 0;     // V − E + F − C of the cell complex
  long euler_boundary = 0;  // V − E + F of the boundary surface
  double min_volume = 0.0;

  bool conforming() const {
    return unmatched_faces == 0 && misoriented_pairs == 0 && overshared_faces == 0 &&
           boundary_mismatches == 0;
  }
  bool watertight() const { return open_boundary_edges == 0; }
  bool valid() const {
    return nonpositive_cells == 0 && conforming() && watertight() &&
           2 * euler_cells == euler_boundary;
  }
  std::string describe() const;
};

// Faces and edges are filed under their smallest node and matched node by node (linear time),
// over `threads` threads (0: every core).
MeshCheck check_mesh(const HybridMesh& mesh, int threads = 0);

}  // namespace naris
