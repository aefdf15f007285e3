#pragma once
// The fine-scale velocity u' = −τ_M r_M of the stabilized equations read as a variational
// multiscale method (Hughes, Mazzei & Jansen 2000; Bazilevs et al. 2007), with r_M the strong
// momentum residual of the converged field. The discrete continuity equation tested with every
// nodal q reads (u + u', ∇q) = ∮ q u·n: it is u + u', not u alone, whose mass the method
// conserves, so a flux through a section is that of u + u' (docs/method/planes.md).
#include <Eigen/Dense>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/flow_field.h"

namespace naris::ns {

// Per cell (tetrahedra, then pyramids, then hexahedra, as in the mesh), ∫_K u' dΩ / |K| of a
// steady field without body force, nondimensional like `field`; `length_scale` is the unit of
// length of the field in the mesh's coordinates (d_in in mm for a solution of naris solve).
std::vector<Eigen::Vector3d> subgrid_velocity(const HybridMesh& mesh, const FlowField& field,
                                              double nu, double length_scale);

}  // namespace naris::ns
