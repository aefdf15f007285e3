// The cost of assembling the Navier–Stokes system: the element kernel (oseen_element.h) per cell
// type, and OseenSystem::assemble as a whole (kernels, recovered gradient, insertion into the
// 4×4-block matrix), for Picard's and Newton's linearization.
// Usage: bench_assembly [mesh.h5] [--repeat N]; without a mesh, the MVE mesh of a ball
// (tests/solver/meshes.h, 48 cells across), which has all three cell types.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "mesh/io/mesh_h5.h"
#include "solver/ns/oseen_system.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/meshes.h"

using namespace naris;

namespace {

// A smooth swirl over the mesh's bounding box, of unit amplitude, and its gradient.
struct Swirl {
  Eigen::Vector3d lo, scale;
  Eigen::Vector3d velocity(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d s = (x - lo).cwiseProduct(scale);
    return {std::sin(s.y()), std::cos(s.z()), std::sin(s.x())};
  }
  Eigen::Matrix<double, 1, 9> gradient(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d s = (x - lo).cwiseProduct(scale);
    Eigen::Matrix<double, 1, 9> g = Eigen::Matrix<double, 1, 9>::Zero();
    g[1] = std::cos(s.y()) * scale.y();   // ∂a_x/∂y
    g[5] = -std::sin(s.z()) * scale.z();  // ∂a_y/∂z
    g[6] = std::cos(s.x()) * scale.x();   // ∂a_z/∂x
    return g;
  }
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The advection and its gradient at every node, computed once.
struct NodalField {
  std::vector<Eigen::Vector3d> velocity;
  std::vector<Eigen::Matrix<double, 1, 9>> gradient;
  std::vector<double> pressure;
};

// Microseconds per cell of the element kernel over every cell of one type, best of `repeat`.
template <class E, class Cells>
double kernel_microseconds(const HybridMesh& mesh, const Cells& cells, const NodalField& field,
                           double nu, ns::Linearization linearization, int repeat) {
  constexpr int N = E::nodes;
  if (cells.empty()) return NAN;
  Eigen::Matrix<double, N, 3> X, a;
  Eigen::Matrix<double, N, 9> grad;
  Eigen::Matrix<double, N, 1> p;
  ns::ElementSystem<N> sys;
  const auto no_force = [](const Eigen::Vector3d&) -> Eigen::Vector3d {
    return Eigen::Vector3d::Zero();
  };
  double best = INFINITY, checksum = 0.0;
  for (int r = 0; r < repeat; ++r) {
    Stopwatch clock;
    for (const auto& cell : cells) {
      for (int i = 0; i < N; ++i) {
        const auto n = static_cast<std::size_t>(cell[static_cast<std::size_t>(i)]);
        X.row(i) = mesh.nodes[n].transpose();
        a.row(i) = field.velocity[n].transpose();
        grad.row(i) = field.gradient[n];
        p[i] = field.pressure[n];
      }
      ns::oseen_element<E>(X, a, &grad, nu, no_force, sys, p, linearization);
      checksum += sys.K(0, 0);
    }
    best = std::min(best, clock.seconds());
  }
  if (!std::isfinite(checksum)) fail("the kernel's matrix is not finite");
  return best / static_cast<double>(cells.size()) * 1e6;
}

}  // namespace

int main(int argc, char** argv) {
  petsc::Session session;
  set_verbosity(Verbosity::quiet);
  std::string path;
  int repeat = 3;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else if (argv[i][0] != '-') {
      path = argv[i];
    } else {
      std::fprintf(stderr, "usage: bench_assembly [mesh.h5] [--repeat N]\n");
      return 2;
    }
  }
  const HybridMesh mesh =
      path.empty() ? testing::convergence_mesh("mve-ball", 48) : read_mesh_h5(path);
  Eigen::Vector3d lo = mesh.nodes[0], hi = lo;
  for (const auto& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const Swirl swirl{lo, (2.0 * M_PI * Eigen::Vector3d::Ones()).cwiseQuotient(hi - lo)};
  const double nu = 1e-3 * (hi - lo).maxCoeff();  // Re 1000 on the box
  std::printf("%s: %zu cells (%zu tetrahedra, %zu pyramids, %zu hexahedra), %zu nodes\n",
              path.empty() ? "MVE ball, 48 cells across" : path.c_str(), mesh.cell_count(),
              mesh.tets.size(), mesh.pyramids.size(), mesh.hexes.size(), mesh.nodes.size());
  NodalField field;
  for (const auto& x : mesh.nodes) {
    field.velocity.push_back(swirl.velocity(x));
    field.gradient.push_back(swirl.gradient(x));
    field.pressure.push_back(x.x());
  }
  std::printf("\nElement kernel (oseen_element), µs per cell, best of %d\n", repeat);
  std::printf("%-14s %10s %10s\n", "cell", "Picard+R", "Newton");
  using ns::Linearization;
  const auto kernel_row = [&](const char* name, auto picard, auto newton) {
    std::printf("%-14s %10.3f %10.3f\n", name, picard, newton);
  };
  kernel_row(
      "tetrahedron",
      kernel_microseconds<fem::Tet4>(mesh, mesh.tets, field, nu, Linearization::picard_residual,
                                     repeat),
      kernel_microseconds<fem::Tet4>(mesh, mesh.tets, field, nu, Linearization::newton, repeat));
  kernel_row("pyramid",
             kernel_microseconds<fem::Pyr5>(mesh, mesh.pyramids, field, nu,
                                            Linearization::picard_residual, repeat),
             kernel_microseconds<fem::Pyr5>(mesh, mesh.pyramids, field, nu, Linearization::newton,
                                            repeat));
  kernel_row(
      "hexahedron",
      kernel_microseconds<fem::Hex8>(mesh, mesh.hexes, field, nu, Linearization::picard_residual,
                                     repeat),
      kernel_microseconds<fem::Hex8>(mesh, mesh.hexes, field, nu, Linearization::newton, repeat));

  // The whole assembly on one rank, as the nonlinear solve calls it.
  const parallel::NodeNumbering numbering = parallel::whole_numbering(mesh.nodes.size());
  ns::OseenSystem system(mesh, numbering, PETSC_COMM_SELF, "bench_", ns::BackflowStabilization{},
                         MATBAIJ);
  std::printf("\nOseenSystem::assemble, median of %d\n", repeat);
  std::printf("%-14s %10s %14s\n", "linearization", "seconds", "cells per s");
  for (const auto& [name, linearization] : {std::pair{"Picard+R", Linearization::picard_residual},
                                            std::pair{"Newton", Linearization::newton}}) {
    std::vector<double> seconds;
    for (int r = 0; r < repeat; ++r) {
      Stopwatch clock;
      system.assemble(field.velocity, field.pressure, nu, nullptr, linearization);
      seconds.push_back(clock.seconds());
    }
    const double s = median(seconds);
    std::printf("%-14s %10.3f %14.0f\n", name, s, static_cast<double>(mesh.cell_count()) / s);
  }
  return 0;
}
