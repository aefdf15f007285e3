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
#include "hybrid_mesh.h"

namespace naris {

// One level of refinement. The refined mesh is conforming when the input is. Nodes are numbered
// after the input's (each new node just after the lowest-numbered node it derives from), so the
// slab-by-slab numbering of the mesher, which the solver's partition and ordering rely on,
// carries over.
HybridMesh subdivide(const HybridMesh& mesh);

}  // namespace naris
