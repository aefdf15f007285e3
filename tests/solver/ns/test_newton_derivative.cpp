// Newton's whole derivative against the residual it differentiates: J δ against the central
// difference (R(x + εδ) − R(x − εδ)) / 2ε, on an MVE pipe (tetrahedra, pyramids and hexahedra)
// with the outlet's backflow stabilization active on part of the outlet, at Re 20 (viscous) and
// Re 610 (advective: the τ's derivatives matter), every row and every term at once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "solver/ns/oseen_system.h"
#include "solver/parallel/partition.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/meshes.h"

namespace naris::ns {
namespace {

using Vec3 = Eigen::Vector3d;

HybridMesh pipe() {
  mve::MveOptions options;
  options.side_patch[4] = "inlet";
  options.side_patch[5] = "outlet";
  return testing::mve_mesh_box(
      [](const Vec3& x) { return 0.5 - std::hypot(x[0] - 0.013, x[1] + 0.007); }, {-0.6, -0.6, 0.0},
      {0.6, 0.6, 1.5}, 0.1, options);
}

// A smooth state with swirl, whose axial velocity turns back over part of the outlet.
FlowField state(const HybridMesh& mesh) {
  FlowField f{std::vector<Vec3>(mesh.nodes.size()), std::vector<double>(mesh.nodes.size())};
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    const Vec3& x = mesh.nodes[i];
    f.velocity[i] =
        Vec3(0.3 * std::sin(3 * x[1]) - 0.2 * x[1], 0.2 * std::cos(2 * x[0]) + 0.2 * x[0],
             1.0 - 3.0 * x.head<2>().squaredNorm() + 1.5 * std::sin(6 * x[0] + x[2]));
    f.pressure[i] = 0.5 * x[2] * x[2] - 0.3 * x[0] + 0.1 * std::cos(x[1]);
  }
  return f;
}

std::vector<double> values(Vec v) {
  PetscInt n = 0;
  petsc::check(VecGetLocalSize(v, &n), "VecGetLocalSize");
  const PetscScalar* x = nullptr;
  petsc::check(VecGetArrayRead(v, &x), "VecGetArrayRead");
  std::vector<double> out(x, x + n);
  petsc::check(VecRestoreArrayRead(v, &x), "VecRestoreArrayRead");
  return out;
}

// max over the velocity rows and over the pressure rows of |J δ − FD| / max |J δ|.
std::array<double, 2> derivative_error(double reynolds) {
  const HybridMesh mesh = pipe();
  const std::size_t n = mesh.nodes.size();
  const parallel::NodeNumbering numbering = parallel::whole_numbering(n);
  const int outlet = mesh.patch_id("outlet");
  const BackflowStabilization backflow{{{outlet, 1.0}}};
  OseenSystem system(mesh, numbering, PETSC_COMM_SELF, "fd_", backflow, MATBAIJ);
  system.use_newton_operator({});
  const double nu = 1.0 / reynolds;
  const FlowField x = state(mesh);
  // The backflow term's switch is crossed: the flow leaves through some outlet faces and enters
  // through others.
  int in = 0, out = 0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> v, std::int32_t patch) {
    if (patch != outlet) return;
    Vec3 u = Vec3::Zero();
    for (NodeId k : v) u += x.velocity[static_cast<std::size_t>(k)];
    (u[2] < 0.0 ? in : out) += 1;
  });
  std::printf("outlet faces: %d with inflow, %d with outflow\n", in, out);
  EXPECT_GT(in, 10);
  EXPECT_GT(out, 10);

  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  FlowField delta = x;
  for (std::size_t i = 0; i < n; ++i) {
    delta.velocity[i] = Vec3(uniform(random), uniform(random), uniform(random));
    delta.pressure[i] = uniform(random);
  }
  petsc::Vector direction, product;
  petsc::check(VecDuplicate(system.solution(), direction.out()), "VecDuplicate");
  petsc::check(VecDuplicate(system.solution(), product.out()), "VecDuplicate");
  system.distribute(delta, direction);

  system.assemble(x.velocity, x.pressure, nu, {}, Linearization::newton);
  petsc::check(MatMult(system.newton_operator(x.velocity, nu), direction, product), "MatMult");
  const std::vector<double> exact = values(product);

  const double eps = 1e-7;
  auto residual_at = [&](double s) {
    FlowField y = x;
    for (std::size_t i = 0; i < n; ++i) {
      y.velocity[i] += s * delta.velocity[i];
      y.pressure[i] += s * delta.pressure[i];
    }
    system.assemble(y.velocity, y.pressure, nu, {}, Linearization::picard_residual);
    return values(system.residual());
  };
  const std::vector<double> plus = residual_at(eps), minus = residual_at(-eps);
  std::array<double, 2> scale{}, error{};
  for (std::size_t r = 0; r < exact.size(); ++r) {
    const std::size_t kind = r % 4 == 3 ? 1 : 0;
    scale[kind] = std::max(scale[kind], std::abs(exact[r]));
    error[kind] = std::max(error[kind], std::abs(exact[r] - (plus[r] - minus[r]) / (2 * eps)));
  }
  std::printf("Re %g: |J δ − FD| / max |J δ|: velocity rows %.2e, pressure rows %.2e\n", reynolds,
              error[0] / scale[0], error[1] / scale[1]);
  return {error[0] / scale[0], error[1] / scale[1]};
}

TEST(NewtonDerivative, EqualsTheResidualsCentralDifferenceAtRe20) {
  petsc::Session session;
  const auto [velocity_rows, pressure_rows] = derivative_error(20.0);
  EXPECT_LT(velocity_rows, 1e-6);
  EXPECT_LT(pressure_rows, 1e-6);
}

TEST(NewtonDerivative, EqualsTheResidualsCentralDifferenceAtRe610) {
  petsc::Session session;
  const auto [velocity_rows, pressure_rows] = derivative_error(610.0);
  EXPECT_LT(velocity_rows, 1e-6);
  EXPECT_LT(pressure_rows, 1e-6);
}

}  // namespace
}  // namespace naris::ns
