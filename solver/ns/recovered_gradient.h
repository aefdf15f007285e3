#pragma once
// The velocity gradient recovered at the nodes: the lumped L2 projection of the cells' ∇a,
// G_i = Σ_K ∫ N_i ∇a / Σ_K ∫ N_i (the stabilization's reconstructed viscous term and the
// traction on open patches use it).
#include <Eigen/Dense>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris::ns {

// Per node, ∂a_c/∂x_d at entry 3c + d, over every cell of `mesh`; `mass` gets ∫ N_i. A node is
// exact only where `mesh` holds every cell around it.
void recover_gradient(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& a,
                      std::vector<Eigen::Matrix<double, 1, 9>>& gradient,
                      std::vector<double>& mass);

}  // namespace naris::ns
