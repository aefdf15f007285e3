#pragma once
// The outflow stabilization's term on one boundary face (Bazilevs, Gohean, Hughes, Moser & Zhang
// 2009): −β ∫ (a·n)₋ u·w, zero wherever the flow leaves. The solver assembles it on the
// outlet; the consistent forces count it as the outlet's traction.
#include <Eigen/Dense>
#include <span>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris::ns {

// (x)₋ = min(0, x) and its slope; with a width δ > 0 its C¹ smoothing, exact outside (−δ, δ)
// and the parabola −(x − δ)²/4δ inside, so that Newton's derivative is continuous where the
// flow through a face turns.
struct NegativePart {
  double value = 0.0, slope = 0.0;
};
inline NegativePart negative_part(double x, double delta) {
  if (x >= delta) return {0.0, 0.0};
  if (x <= -delta) return {x, 1.0};
  return {-(x - delta) * (x - delta) / (4.0 * delta), (delta - x) / (2.0 * delta)};
}

// M(i, j) = −β ∫ (a·n)₋ φ_i φ_j over the face `v` (n outward; corners i, j < v.size()), and
// with `derivative` Newton's share d/du of the term with a = u, −β ∫ (u·n)₋' (δu·n) (u·w), with
// rows and columns 4i + c; (·)₋ smoothed over `smoothing` (negative_part). Fan triangles from
// v[0], three edge-midpoint points each.
void backflow_face(const HybridMesh& mesh, std::span<const NodeId> v,
                   const std::vector<Eigen::Vector3d>& advection, double beta, double smoothing,
                   Eigen::Matrix4d& M, Eigen::Matrix<double, 16, 16>* derivative);

}  // namespace naris::ns
