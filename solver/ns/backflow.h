#pragma once
// The outflow stabilization's term on one boundary face (Bazilevs, Gohean, Hughes, Moser & Zhang
// 2009): −β ∫ (a·n)₋ u·w, zero wherever the flow leaves. The solver assembles it on the
// outlet; the consistent forces count it as the outlet's traction.
#include <Eigen/Dense>
#include <span>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris::ns {

// M(i, j) = −β ∫ (a·n)₋ φ_i φ_j over the face `v` (n outward; corners i, j < v.size()), and
// with `derivative` Newton's share d/du of the term with a = u, −β ∫ H(−u·n) (δu·n) (u·w), with
// rows and columns 4i + c. Fan triangles from v[0], three edge-midpoint points each.
void backflow_face(const HybridMesh& mesh, std::span<const NodeId> v,
                   const std::vector<Eigen::Vector3d>& advection, double beta, Eigen::Matrix4d& M,
                   Eigen::Matrix<double, 16, 16>* derivative);

}  // namespace naris::ns
