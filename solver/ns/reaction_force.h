#pragma once
// The force of the fluid on each boundary patch by the consistent (reaction) method: the
// momentum residual of the converged discrete equations tested with the patch's boundary basis
// functions, Σ_i R_i. The weak form makes R_i = ∫_Γ σn N_i exactly, so the force converges at
// the solution's order and the patches' forces balance the momentum equations to the solver's
// tolerance; the surface integral of the cell gradients on the wall's thin cells does neither
// (wall_stress.h keeps it for comparison). Method: docs/method/discretization.md.
#include <mpi.h>

#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/ns/flow_problem.h"
#include "solver/parallel/partition.h"

namespace naris::ns {

// How a patch's traction enters the discrete problem.
enum class PatchKind {
  wall,        // no slip: the traction is the unknown reaction
  prescribed,  // velocity given (an inlet): the traction is a reaction too
  natural,     // traction-free (the outlet), or the backflow term's traction alone
};

// The airflow problem's kinds (boundary_conditions.h): the driven one of `inlet` and `outlet`
// prescribed, the other natural, every other patch a wall.
std::vector<PatchKind> airflow_patch_kinds(const HybridMesh& mesh,
                                           DrivenPatch driven = DrivenPatch::inlet);

struct Reactions {
  // Per patch id, the nondimensional force (units ρU²d²) the fluid exerts on the patch, summed
  // over the ranks and known on every rank.
  std::vector<Eigen::Vector3d> patches;
  // Per node of the piece, the viscous force per area the fluid exerts on the walls there: the
  // walls' share of the reaction less the pressure's ∫ p n N_i, over their ∫ N_i (units ρU²);
  // zero off the walls.
  std::vector<Eigen::Vector3d> viscous_traction;
};

// The reactions of the converged field; the forces are summed over the ranks of `comm`. `field` and
// `problem` are the piece's (local numbers, its Dirichlet conditions); a node shared by patches
// gives a prescribed patch the surface integral of the traction against its basis function there, a
// natural patch nothing but the backflow term's traction (`problem.backflow`), and the
// walls the rest, in proportion to ∫ N_i over each. Collective.
Reactions reaction_forces(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                          const FlowField& field, const FlowProblem& problem,
                          const std::vector<PatchKind>& kinds, MPI_Comm comm);

// The wall shear stress of the consistent traction, per boundary face of `piece` (triangles,
// then quadrilaterals, as wall_stress.h): the mean of the face's nodal viscous tractions less
// its part along the face's normal; zero on faces of patches that are not walls.
std::vector<Eigen::Vector3d> consistent_wall_shear(const HybridMesh& piece,
                                                   const Reactions& reactions,
                                                   const std::vector<PatchKind>& kinds);

}  // namespace naris::ns
