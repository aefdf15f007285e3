// Run with two MPI ranks (ctest does): the solve shared by the ranks of PETSC_COMM_WORLD —
// each on its piece of the mesh, cells assembled where their smallest node lives, the halo of
// the iterate refreshed after each step, additive Schwarz preconditioning —
// reaches the same discrete solution as the solve each rank does alone on PETSC_COMM_SELF, to
// the nonlinear tolerance, and Newton converges quadratically on the pieces; the
// Ethier–Steinman flow on an MVE ball has every cell type.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/ns/distributed_field.h"
#include "solver/ns/node_graph.h"
#include "solver/ns/reaction_force.h"
#include "solver/parallel/block_assembly.h"
#include "solver/parallel/partition.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/manufactured.h"
#include "tests/solver/meshes.h"
#include "tests/solver/residual_history.h"

namespace naris::ns {
namespace {

using nonlinear::NonlinearOptions;
using nonlinear::NonlinearReport;
using nonlinear::solve_navier_stokes;

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
  NonlinearOptions options;
  options.tolerance = 1e-10;
  NonlinearReport serial_report, parallel_report;
  ns::FlowProblem problem{1.0 / nu, force, bc};
  problem.communicator = PETSC_COMM_SELF;
  const FlowField serial = solve_navier_stokes(mesh, problem, options, &serial_report);
  problem.communicator = PETSC_COMM_WORLD;
  const FlowField parallel = solve_navier_stokes(mesh, problem, options, &parallel_report);
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
  NonlinearReport exact;
  solve_navier_stokes(mesh, problem, options, &exact);
  EXPECT_TRUE(testing::ends_quadratically(exact.residuals));
}

// The consistent forces summed from the pieces — each rank's cells' residuals and faces, added
// on the nodes' owners across the ranks' boundary — are the whole mesh's on one rank, for any
// field (no solve needed), on a pipe whose inlet rim is shared by a prescribed patch and a wall.
TEST(Mpi, ReactionForcesOfThePiecesAreTheWholeMeshs) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  ASSERT_GE(ranks, 2) << "run this test under mpiexec -n 2";
  mve::MveOptions options;
  options.side_patch[4] = "inlet";
  options.side_patch[5] = "outlet";
  const HybridMesh whole = testing::mve_mesh_box(
      [](const Eigen::Vector3d& x) { return 0.5 - std::hypot(x[0] - 0.013, x[1] + 0.007); },
      {-0.6, -0.6, 0.0}, {0.6, 0.6, 1.5}, 0.1, options);
  FlowField field;
  for (const auto& x : whole.nodes) {
    field.velocity.push_back(testing::beltrami(x));
    field.pressure.push_back(testing::beltrami_pressure(x));
  }
  // The Beltrami field flows back in through parts of the outlet: the outflow stabilization's
  // traction is counted there.
  const FlowProblem problem{100.0,
                            {},
                            airflow_conditions(whole, InletProfile::uniform, 1.0),
                            {{{whole.patch_id("outlet"), 1.0}}}};
  const std::vector<PatchKind> kinds = airflow_patch_kinds(whole);
  const Reactions whole_reactions = reaction_forces(
      whole, parallel::whole_numbering(whole.nodes.size()), field, problem, kinds, PETSC_COMM_SELF);
  const std::vector<Eigen::Vector3d>& serial = whole_reactions.patches;
  const auto piece = parallel::mesh_piece(whole, rank, ranks);
  FlowProblem local = problem;
  local.conditions = local_conditions(problem.conditions, piece.numbering);
  const Reactions piece_reactions =
      reaction_forces(piece.mesh, piece.numbering, local_field(field, piece.numbering), local,
                      kinds, PETSC_COMM_WORLD);
  const std::vector<Eigen::Vector3d>& shared = piece_reactions.patches;
  ASSERT_EQ(shared.size(), serial.size());
  // The walls' traction at every node of the piece, halo included.
  double largest = 0.0, difference = 0.0;
  for (std::size_t n = 0; n < piece.mesh.nodes.size(); ++n) {
    const auto g = static_cast<std::size_t>(piece.numbering.to_global(static_cast<NodeId>(n)));
    largest = std::max(largest, whole_reactions.viscous_traction[g].norm());
    difference = std::max(
        difference,
        (piece_reactions.viscous_traction[n] - whole_reactions.viscous_traction[g]).norm());
  }
  EXPECT_GT(largest, 0.0);
  EXPECT_LE(difference, 1e-12 * largest);
  for (std::size_t q = 0; q < serial.size(); ++q) {
    if (rank == 0)
      std::printf("[ info ] %s: %.6e %.6e %.6e on one rank, difference %.1e on %d\n",
                  whole.patch_names[q].c_str(), serial[q][0], serial[q][1], serial[q][2],
                  (shared[q] - serial[q]).norm(), ranks);
    EXPECT_LE((shared[q] - serial[q]).norm(), 1e-12 * (1.0 + serial[q].norm()))
        << whole.patch_names[q];
  }
  EXPECT_GT(serial[static_cast<std::size_t>(whole.patch_id("outlet"))].norm(), 0.0);
}

// The solver's 4×4-block matrix of type `type` over the piece's owned nodes; every cell the rank
// owns adds a matrix that depends only on the cell's global nodes, through BlockAssembly (`direct`)
// or through MatSetValuesBlocked.
petsc::Matrix element_sum(const HybridMesh& mesh, const parallel::NodeNumbering& numbering,
                          MPI_Comm comm, MatType type, bool direct, int passes,
                          bool* last_pass_direct = nullptr) {
  petsc::Matrix m = block_matrix(mesh, numbering, comm, type, "");
  parallel::BlockAssembly insertion(m, numbering);
  for (int pass = 0; pass < passes; ++pass) {
    petsc::check(MatZeroEntries(m), "MatZeroEntries");
    insertion.begin();
    if (last_pass_direct) *last_pass_direct = insertion.adds_directly();
    auto add = [&](const auto& cells) {
      constexpr std::size_t N = std::tuple_size_v<std::decay_t<decltype(cells[0])>>;
      Eigen::Matrix<double, 4 * N, 4 * N> K;
      Eigen::Matrix<double, 4 * N, 4 * N, Eigen::RowMajor> row_major;
      std::array<PetscInt, N> global{};
      for (const auto& cell : cells) {
        if (!numbering.owns_cell(cell)) continue;
        for (std::size_t i = 0; i < N; ++i) global[i] = numbering.to_global(cell[i]);
        for (int r = 0; r < K.rows(); ++r)
          for (int c = 0; c < K.cols(); ++c)
            K(r, c) =
                std::sin(0.37 * global[static_cast<std::size_t>(r / 4)] + 0.11 * (r % 4) +
                         1.3 * global[static_cast<std::size_t>(c / 4)] + 0.7 * (c % 4) + pass);
        if (direct) {
          insertion.add(std::span<const NodeId>(cell.data(), N), K.data());
        } else {
          row_major = K;
          petsc::check(MatSetValuesBlocked(m, N, global.data(), N, global.data(), row_major.data(),
                                           ADD_VALUES),
                       "MatSetValuesBlocked");
        }
      }
    };
    add(mesh.tets);
    add(mesh.pyramids);
    add(mesh.hexes);
    insertion.end();
    petsc::check(MatAssemblyBegin(m, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    petsc::check(MatAssemblyEnd(m, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  }
  return m;
}

// Element matrices written straight into the block arrays (after the first assembly, which
// fixes the pattern) sum to the matrix MatSetValuesBlocked builds, on one rank and on the
// pieces of several, and a matrix type without blocks takes them through PETSc unchanged.
TEST(Mpi, BlockAssemblyAddsWhatMatSetValuesBlockedAdds) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  const HybridMesh whole = testing::convergence_mesh("mve-ball", 6);
  ASSERT_GT(whole.pyramids.size(), 0u);
  const auto piece = parallel::mesh_piece(whole, rank, ranks);
  const auto serial = parallel::whole_numbering(whole.nodes.size());
  struct Case {
    const HybridMesh& mesh;
    const parallel::NodeNumbering& numbering;
    MPI_Comm comm;
  };
  for (const Case& c : {Case{whole, serial, PETSC_COMM_SELF},
                        Case{piece.mesh, piece.numbering, PETSC_COMM_WORLD}}) {
    const auto reference = element_sum(c.mesh, c.numbering, c.comm, MATBAIJ, false, 2);
    for (MatType type : {MATBAIJ, MATAIJ}) {
      bool straight = false;
      const auto direct = element_sum(c.mesh, c.numbering, c.comm, type, true, 2, &straight);
      EXPECT_EQ(straight, std::string(type) == MATBAIJ);
      PetscReal size = 0.0, difference = 0.0;
      petsc::check(MatNorm(reference, NORM_FROBENIUS, &size), "MatNorm");
      petsc::Matrix d;
      petsc::check(MatConvert(direct, MATBAIJ, MAT_INITIAL_MATRIX, d.out()), "MatConvert");
      petsc::check(MatAXPY(d, -1.0, reference, DIFFERENT_NONZERO_PATTERN), "MatAXPY");
      petsc::check(MatNorm(d, NORM_FROBENIUS, &difference), "MatNorm");
      EXPECT_GT(size, 1.0);
      EXPECT_LE(difference, 1e-14 * size)
          << type << " on " << (c.comm == PETSC_COMM_SELF ? 1 : ranks) << " ranks";
    }
  }
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
