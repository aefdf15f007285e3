#pragma once
// Manufactured and exact flows for the solver's tests and convergence benchmark: Dirichlet data
// from an exact field (with a zero discrete net flux), L2 errors, and the steady Ethier–Steinman
// (Beltrami) flow of VERIFICATION.md §2.
#include <functional>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/flow_field.h"

namespace naris::testing {

using Exact = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;
using ExactScalar = std::function<double(const Eigen::Vector3d&)>;

// ∫ N_i n dA over the boundary for every node: the flux of a unit nodal velocity.
std::vector<Eigen::Vector3d> boundary_flux_weights(const HybridMesh& mesh);

// The exact velocity on every boundary node, corrected along the nodal normals so that the
// discrete net flux is zero: with every velocity fixed, the continuity equations sum to that
// flux, and an interpolation error there would pile up at the node whose pressure is pinned.
// The pressure is pinned at the node nearest the origin.
ns::DirichletConditions exact_on_boundary(const HybridMesh& mesh, const Exact& u,
                                          const ExactScalar& p);

struct Errors {
  double velocity = 0, pressure = 0;  // L2 norms; pressure up to its mean
};
// L2 errors by a degree-4 rule on every cell; the pressure's mean offset is removed first.
Errors l2_errors(const HybridMesh& mesh, const ns::FlowField& f, const Exact& u,
                 const ExactScalar& p);

// The steady Ethier–Steinman flow on [−1,1]³, a = π/4, d = π/2: it solves the steady equations
// with body force f = ν d² u and pressure p = −|u|²/2.
inline constexpr double kBeltramiA = 0.78539816339744831, kBeltramiD = 1.5707963267948966;
Eigen::Vector3d beltrami(const Eigen::Vector3d& x);
double beltrami_pressure(const Eigen::Vector3d& x);

}  // namespace naris::testing
