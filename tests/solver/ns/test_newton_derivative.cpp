// Newton's whole derivative against the residual it differentiates: J δ against the central
// difference (R(x + εδ) − R(x − εδ)) / 2ε, on an MVE pipe (tetrahedra, pyramids and hexahedra)
// with the outlet's backflow stabilization active on part of the outlet, at Re 20 (viscous) and
// Re 610 (advective: the τ's derivatives matter), every row and every term at once; and with the
// switch of the backflow term smoothed, its smoothing's derivative.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <vector>

#include "solver/ns/backflow.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/ns/oseen_system.h"
#include "solver/parallel/partition.h"
#include "solver/parallel/petsc.h"
#include "solver/stability/linear_stability.h"
#include "tests/solver/meshes.h"

namespace naris::ns {
namespace {

using Vec3 = Eigen::Vector3d;

HybridMesh swirl_pipe(double h = 0.1) {
  mve::MveOptions options;
  options.side_patch[4] = "inlet";
  options.side_patch[5] = "outlet";
  return testing::mve_mesh_box(
      [](const Vec3& x) { return 0.5 - std::hypot(x[0] - 0.013, x[1] + 0.007); }, {-0.6, -0.6, 0.0},
      {0.6, 0.6, 1.5}, h, options);
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
std::array<double, 2> derivative_error(double reynolds, double smoothing = 0.0) {
  const HybridMesh mesh = swirl_pipe();
  const std::size_t n = mesh.nodes.size();
  const parallel::NodeNumbering numbering = parallel::whole_numbering(n);
  const int outlet = mesh.patch_id("outlet");
  const BackflowStabilization backflow{{{outlet, 1.0}}, smoothing};
  OseenSystem system(mesh, numbering, PETSC_COMM_SELF, "fd_", backflow, MATBAIJ);
  system.use_newton_operator({});
  const double nu = 1.0 / reynolds;
  const FlowField x = state(mesh);
  // The backflow term's switch is crossed: the flow leaves through some outlet faces and enters
  // through others.
  int in = 0, out = 0, smoothed = 0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> v, std::int32_t patch) {
    if (patch != outlet) return;
    Vec3 u = Vec3::Zero();
    for (NodeId k : v) u += x.velocity[static_cast<std::size_t>(k)];
    u /= static_cast<double>(v.size());
    (u[2] < 0.0 ? in : out) += 1;
    smoothed += std::abs(u[2]) < smoothing;
  });
  std::printf("outlet faces: %d with inflow, %d with outflow, %d within the smoothing\n", in, out,
              smoothed);
  EXPECT_GT(in, 10);
  EXPECT_GT(out, 10);
  if (smoothing > 0.0) {
    EXPECT_GT(smoothed, 10);
  }

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

TEST(NewtonDerivative, EqualsTheResidualsCentralDifferenceWithTheSwitchSmoothed) {
  petsc::Session session;
  const auto [velocity_rows, pressure_rows] = derivative_error(610.0, 0.3);
  EXPECT_LT(velocity_rows, 1e-6);
  EXPECT_LT(pressure_rows, 1e-6);
}

// SLEPc's eigenvalues of J v = λ M v nearest zero against the dense QZ algorithm on the same
// J (column by column from the shell operator) and M, on a pipe small enough to hold densely.
TEST(LinearStability, EigenvaluesNearestZeroMatchTheDenseGeneralizedProblem) {
  petsc::Session session;
  const HybridMesh mesh = swirl_pipe(0.25);
  const std::size_t n = mesh.nodes.size();
  const parallel::NodeNumbering numbering = parallel::whole_numbering(n);
  FlowProblem problem;
  problem.reynolds = 200.0;
  problem.backflow = {{{mesh.patch_id("outlet"), 1.0}}, 0.1};
  // The pipe's inlet and wall fixed (their values do not enter J), the outlet free.
  problem.conditions = airflow_conditions(mesh, InletProfile::uniform, 1.0);
  const FlowField x = state(mesh);
  const std::vector<stability::Mode> modes =
      stability::leading_modes(mesh, numbering, problem, x, {.modes = 4, .tolerance = 1e-10});
  ASSERT_GE(modes.size(), 4u);

  // The same J and M, densely.
  OseenSystem system(mesh, numbering, PETSC_COMM_SELF, "dense_", problem.backflow, MATBAIJ);
  std::vector<PetscInt> rows;
  for (NodeId k : problem.conditions.nodes)
    for (int c = 0; c < 3; ++c) rows.push_back(4 * k + c);
  system.use_newton_operator(rows);
  const double nu = 1.0 / problem.reynolds;
  system.assemble(x.velocity, x.pressure, nu, {}, Linearization::newton);
  petsc::check(MatZeroRows(system.matrix(), static_cast<PetscInt>(rows.size()), rows.data(), 1.0,
                           nullptr, nullptr),
               "MatZeroRows");
  Mat jacobian = system.newton_operator(x.velocity, nu);
  const Eigen::Index size = static_cast<Eigen::Index>(4 * n);
  Eigen::MatrixXd J(size, size), M = Eigen::MatrixXd::Zero(size, size);
  petsc::Vector unit, column;
  petsc::check(VecDuplicate(system.solution(), unit.out()), "VecDuplicate");
  petsc::check(VecDuplicate(system.solution(), column.out()), "VecDuplicate");
  for (Eigen::Index j = 0; j < size; ++j) {
    petsc::check(VecSet(unit, 0.0), "VecSet");
    petsc::check(VecSetValue(unit, static_cast<PetscInt>(j), 1.0, INSERT_VALUES), "VecSetValue");
    petsc::check(VecAssemblyBegin(unit), "VecAssemblyBegin");
    petsc::check(VecAssemblyEnd(unit), "VecAssemblyEnd");
    petsc::check(MatMult(jacobian, unit, column), "MatMult");
    const std::vector<double> c = values(column);
    for (Eigen::Index i = 0; i < size; ++i) J(i, j) = c[static_cast<std::size_t>(i)];
  }
  petsc::Vector mass;
  petsc::check(VecDuplicate(system.solution(), mass.out()), "VecDuplicate");
  system.velocity_mass(mass);
  const std::vector<double> m = values(mass);
  for (Eigen::Index i = 0; i < size; ++i) M(i, i) = m[static_cast<std::size_t>(i)];
  for (PetscInt r : rows) M(r, r) = 0.0;

  Eigen::GeneralizedEigenSolver<Eigen::MatrixXd> qz(J, M, false);
  std::vector<std::complex<double>> dense;
  for (Eigen::Index i = 0; i < size; ++i)
    if (std::abs(qz.betas()[i]) > 1e-12 * std::abs(qz.alphas()[i]))
      dense.push_back(qz.alphas()[i] / qz.betas()[i]);
  std::sort(dense.begin(), dense.end(), [](auto a, auto b) { return std::abs(a) < std::abs(b); });
  for (std::size_t i = 0; i < 4; ++i) {
    std::printf("λ%zu: SLEPc %.10g %+.10gi, dense %.10g %+.10gi\n", i, modes[i].eigenvalue.real(),
                modes[i].eigenvalue.imag(), dense[i].real(), dense[i].imag());
    EXPECT_LT(modes[i].residual, 1e-8);
    // A complex pair may come in either order.
    const auto nearest = *std::min_element(dense.begin(), dense.begin() + 6, [&](auto a, auto b) {
      return std::abs(a - modes[i].eigenvalue) < std::abs(b - modes[i].eigenvalue);
    });
    EXPECT_LT(std::abs(nearest - modes[i].eigenvalue), 1e-7 * std::abs(nearest));
    EXPECT_NEAR(std::abs(modes[i].eigenvalue), std::abs(dense[i]), 1e-7 * std::abs(dense[i]));
  }
}

TEST(BackflowSwitch, IsExactOutsideItsSmoothingAndContinuouslyDifferentiable) {
  const double delta = 0.1;
  for (double x : {-2.0, -0.1, 0.1, 0.5}) {
    EXPECT_EQ(negative_part(x, delta).value, std::min(0.0, x)) << x;
    EXPECT_EQ(negative_part(x, delta).slope, x < 0.0 ? 1.0 : 0.0) << x;
  }
  // Value and slope continuous across ±δ, the slope the value's derivative inside.
  for (double edge : {-delta, delta}) {
    const NegativePart below = negative_part(edge - 1e-12, delta),
                       above = negative_part(edge + 1e-12, delta);
    EXPECT_NEAR(below.value, above.value, 1e-11);
    EXPECT_NEAR(below.slope, above.slope, 1e-10);
  }
  for (double x : {-0.09, -0.03, 0.0, 0.04, 0.08}) {
    const double h = 1e-6;
    const double fd =
        (negative_part(x + h, delta).value - negative_part(x - h, delta).value) / (2 * h);
    EXPECT_NEAR(negative_part(x, delta).slope, fd, 1e-8) << x;
    EXPECT_LE(negative_part(x, delta).value, std::min(0.0, x) + delta / 4.0);
  }
  // Without smoothing, the plain switch, with no slope where the flow is tangential.
  EXPECT_EQ(negative_part(0.0, 0.0).slope, 0.0);
  EXPECT_EQ(negative_part(-1e-300, 0.0).value, -1e-300);
}

}  // namespace
}  // namespace naris::ns
