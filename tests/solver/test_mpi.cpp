// Run with two MPI ranks (ctest does): the solve shared by the ranks of PETSC_COMM_WORLD —
// each on its piece of the mesh, cells assembled where their smallest node lives, the halo of
// the iterate refreshed after each step, additive Schwarz preconditioning —
// reaches the same discrete solution as the solve each rank does alone on PETSC_COMM_SELF, to
// the nonlinear tolerance, and Newton converges quadratically on the pieces; the
// Ethier–Steinman flow on an MVE ball has every cell type.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "manufactured.h"
#include "meshes.h"
#include "ns/navier_stokes.h"
#include "parallel/petsc.h"

namespace naris::ns {
namespace {

std::unique_ptr<petsc::Session> g_session;

TEST(Mpi, SeveralRanksReachTheSerialSolution) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  ASSERT_GE(ranks, 2) << "run this test under mpiexec -n 2";
  const double nu = 0.01;
  const BodyForce force = [nu](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return nu * testing::kBeltramiD * testing::kBeltramiD * testing::beltrami(x);
  };
  const HybridMesh mesh = testing::convergence_mesh("mve-ball", 8);
  const auto bc = testing::exact_on_boundary(mesh, testing::beltrami, testing::beltrami_pressure);
  PicardOptions options;
  options.tolerance = 1e-10;
  PicardReport serial_report, parallel_report;
  options.communicator = PETSC_COMM_SELF;
  const FlowField serial = solve_navier_stokes(mesh, nu, force, bc, options, &serial_report);
  options.communicator = PETSC_COMM_WORLD;
  const FlowField parallel = solve_navier_stokes(mesh, nu, force, bc, options, &parallel_report);
  EXPECT_TRUE(serial_report.converged);
  EXPECT_TRUE(parallel_report.converged);
  double scale = 0.0, du = 0.0, pscale = 0.0, dp = 0.0;
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    scale = std::max(scale, serial.velocity[n].norm());
    du = std::max(du, (parallel.velocity[n] - serial.velocity[n]).norm());
    pscale = std::max(pscale, std::abs(serial.pressure[n]));
    dp = std::max(dp, std::abs(parallel.pressure[n] - serial.pressure[n]));
  }
  if (rank == 0)
    std::printf(
        "[ info ] %d ranks, %zu cells: %d vs %d nonlinear steps; max difference u %.2e "
        "of %.3f, p %.2e of %.3f\n",
        ranks, mesh.cell_count(), parallel_report.iterations, serial_report.iterations, du, scale,
        dp, pscale);
  EXPECT_LT(du, 1e-7 * scale);
  EXPECT_LT(dp, 1e-6 * pscale);
  // Every rank holds the same field, gathered from the pieces.
  double mine = 0.0;
  for (const auto& v : parallel.velocity) mine += v.sum();
  double lowest = 0.0, highest = 0.0;
  MPI_Allreduce(&mine, &lowest, 1, MPI_DOUBLE, MPI_MIN, PETSC_COMM_WORLD);
  MPI_Allreduce(&mine, &highest, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  EXPECT_EQ(lowest, highest);
  // Newton's whole derivative on the pieces — the reconstructed term's couples nodes two cells
  // apart, across the ranks' boundary: with exact linear solves the convergence is quadratic,
  // each ratio of residuals below a tenth of the one before near the end, as on one rank.
  options.linear_tolerance = options.loosest_linear_tolerance = 1e-12;
  options.tolerance = 1e-13;
  PicardReport exact;
  solve_navier_stokes(mesh, nu, force, bc, options, &exact);
  const auto& h = exact.residuals;
  std::size_t last = 0;
  while (last + 1 < h.size() && h[last + 1] > 1e-11 * h.front()) ++last;
  ASSERT_GE(last, 3u);
  EXPECT_LT(h[last] / h[last - 1], 0.1 * h[last - 1] / h[last - 2])
      << h[last - 2] << ", " << h[last - 1] << ", " << h[last];
}

}  // namespace
}  // namespace naris::ns

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  naris::ns::g_session = std::make_unique<naris::petsc::Session>(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  // One rank reports; the others' failures still set the exit code.
  if (rank != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  const int status = RUN_ALL_TESTS();
  naris::ns::g_session.reset();
  return status;
}
