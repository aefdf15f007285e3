#pragma once
// Meshes of a box for the solver tests: hexahedra only, tetrahedra only (each cube split into
// six along its main diagonal, conforming), and MVE hybrids of any signed field.
#include <functional>
#include <string>

#include "mesh/hybrid_mesh.h"
#include "mesh/mve/mve.h"

namespace naris::testing {

// [−1,1]³ with n cubes per side; boundary faces all on patch "wall".
HybridMesh box_hex(int n);
HybridMesh box_tet(int n);
// The MVE mesh of {x : inside(x) > 0} sampled on a grid of spacing h over [lo, hi]³.
HybridMesh mve_mesh(const std::function<double(const Eigen::Vector3d&)>& inside, double lo,
                    double hi, double h);
// The MVE mesh of {x : inside(x) > 0} on a grid of spacing h over the box [lo, hi].
HybridMesh mve_mesh_box(const std::function<double(const Eigen::Vector3d&)>& inside,
                        const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double h,
                        const mve::MveOptions& options);
// The meshes of the convergence study at n cells across [−1,1]: "hex", "tet", "mve-box" (a box
// whose faces cut the grid off its nodes) or "mve-ball" (a ball of radius 0.95).
HybridMesh convergence_mesh(const std::string& kind, int n);
// Nodes on boundary faces, sorted and unique.
std::vector<NodeId> boundary_nodes(const HybridMesh& mesh);

}  // namespace naris::testing
