// The consistent (reaction) force against the surface integral of the cells' gradients: the drag
// on a sphere in a pipe on three meshes, 6, 8 and 10 cells across the sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/ns/oseen_element.h"
#include "solver/ns/patch_integrals.h"
#include "solver/ns/reaction_force.h"
#include "solver/ns/wall_stress.h"
#include "solver/parallel/partition.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/meshes.h"

namespace naris::ns {
namespace {

const Eigen::Vector3d kCentre(0.013, -0.007, 1.0);
constexpr double kRadius = 0.15;  // the pipe's diameter is 1

// A pipe along z from 0 to 2.5 with a sphere on its axis; the sphere's faces become the
// patch `body`.
HybridMesh sphere_in_pipe(double h) {
  mve::MveOptions options;
  options.side_patch[4] = "inlet";
  options.side_patch[5] = "outlet";
  HybridMesh mesh = testing::mve_mesh_box(
      [](const Eigen::Vector3d& x) {
        return std::min(0.5 - std::hypot(x[0] - 0.013, x[1] + 0.007),
                        (x - kCentre).norm() - kRadius);
      },
      {-0.6, -0.6, 0.0}, {0.6, 0.6, 2.5}, h, options);
  const int wall = mesh.patch_id("wall");
  const auto body = static_cast<std::int32_t>(mesh.patch_names.size());
  mesh.patch_names.push_back("body");
  const auto near_sphere = [&](std::span<const NodeId> v) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (NodeId n : v) c += mesh.nodes[static_cast<std::size_t>(n)];
    return (c / static_cast<double>(v.size()) - kCentre).norm() < 2 * kRadius;
  };
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f)
    if (mesh.boundary_tri_patch[f] == wall && near_sphere(mesh.boundary_tris[f]))
      mesh.boundary_tri_patch[f] = body;
  for (std::size_t f = 0; f < mesh.boundary_quads.size(); ++f)
    if (mesh.boundary_quad_patch[f] == wall && near_sphere(mesh.boundary_quads[f]))
      mesh.boundary_quad_patch[f] = body;
  return mesh;
}

// ∫ (u·∇)u dΩ by the cells' quadrature: what the momentum residuals of all nodes sum to (every
// other term of the residual sums to zero over a partition of unity).
Eigen::Vector3d convective_integral(const HybridMesh& mesh, const FlowField& f) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  auto run = [&](const auto& cells, auto element) {
    using E = decltype(element);
    constexpr int N = E::nodes;
    const ShapeTable<E>& table = ShapeTable<E>::get();
    Eigen::Matrix<double, N, 3> X, U;
    for (const auto& cell : cells) {
      for (int i = 0; i < N; ++i) {
        X.row(i) = mesh.nodes[static_cast<std::size_t>(cell[i])].transpose();
        U.row(i) = f.velocity[static_cast<std::size_t>(cell[i])].transpose();
      }
      for (std::size_t q = 0; q < table.points.size(); ++q) {
        const auto m = fem::map_to_cell<E>(X, table.shapes[q]);
        sum += table.points[q].weight * m.det_jacobian * (U.transpose() * m.gradient) *
               (U.transpose() * m.value);
      }
    }
  };
  run(mesh.tets, fem::Tet4{});
  run(mesh.pyramids, fem::Pyr5{});
  run(mesh.hexes, fem::Hex8{});
  return sum;
}

struct Drag {
  double consistent = 0.0, surface = 0.0, balance = 0.0, identity = 0.0;
};

Drag drag_at(int across, double re) {
  const HybridMesh mesh = sphere_in_pipe(2 * kRadius / across);
  const DirichletConditions bc = airflow_conditions(mesh, InletProfile::developed, 1.0);
  nonlinear::NonlinearReport report;
  // With the outlet's outflow stabilization, as naris solve has it.
  const FlowProblem problem{re, {}, bc, {{{mesh.patch_id("outlet"), 1.0}}}};
  const FlowField f = nonlinear::solve_navier_stokes(mesh, problem, {}, &report);
  EXPECT_TRUE(report.converged) << across << " cells across";
  const std::vector<Eigen::Vector3d> forces =
      reaction_forces(mesh, parallel::whole_numbering(mesh.nodes.size()), f, problem,
                      airflow_patch_kinds(mesh), PETSC_COMM_WORLD)
          .patches;
  const auto body = static_cast<std::size_t>(mesh.patch_id("body"));
  const WallStress stress = wall_stress(mesh, f, re);
  Eigen::Vector3d balance = patch_momentum_flux(mesh, f.velocity, mesh.patch_id("inlet")) +
                            patch_momentum_flux(mesh, f.velocity, mesh.patch_id("outlet"));
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const auto& force : forces) total += force;
  balance += total;
  const Drag d{forces[body][2], stress.patches[body].pressure[2] + stress.patches[body].viscous[2],
               balance.norm() / forces[body].norm(),
               (total + convective_integral(mesh, f)).norm() / forces[body].norm()};
  std::printf(
      "[ info ] %2d cells across the sphere, %zu cells: drag %.6f consistent, %.6f surface "
      "integral; momentum balance %.1e, forces + convective integral %.1e of the drag\n",
      across, mesh.cell_count(), d.consistent, d.surface, d.balance, d.identity);
  return d;
}

// The consistent drag is converged at 6, 8 and 10 cells across the sphere: the three agree to
// 1e-3 of their mean (meshes whose boundary cubes kept slivers spread by 2.6e-3, falling
// monotonically towards the same value). The patches' forces are minus the convective integral,
// which the residuals of all nodes sum to (to the solver's tolerance), and close the momentum
// balance.
TEST(ReactionForce, DragOnASphereInAPipeConverges) {
  const double re = 20.0;  // on the pipe's diameter and mean speed
  const Drag coarse = drag_at(6, re), middle = drag_at(8, re), fine = drag_at(10, re);
  const double mean = (coarse.consistent + middle.consistent + fine.consistent) / 3.0;
  for (const Drag& d : {coarse, middle, fine}) {
    EXPECT_LT(std::abs(d.consistent - mean), 1e-3 * mean);
    EXPECT_LT(d.identity, 1e-6);
    EXPECT_LT(d.balance, 1e-3);
  }
}

}  // namespace
}  // namespace naris::ns
