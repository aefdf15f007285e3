// Convergence of the stabilized equal-order discretization on the steady Ethier–Steinman flow
// (VERIFICATION.md §2): L2 errors of velocity and pressure and their observed orders on
// hexahedral, tetrahedral and MVE-hybrid meshes, at ν = 1 and ν = 0.01.
// Usage: bench_ns_convergence [mesh ...] where mesh is hex, tet, mve-box or mve-ball (default all);
// NARIS_BENCH_SIZES=4,8,16 sets the refinements (cells per unit length along the box's side).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "core/log.h"
#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/manufactured.h"
#include "tests/solver/meshes.h"

using namespace naris;

int main(int argc, char** argv) {
  petsc::Session session;
  set_verbosity(Verbosity::quiet);
  std::vector<std::string> kinds;
  for (int i = 1; i < argc; ++i) kinds.push_back(argv[i]);
  if (kinds.empty()) kinds = {"hex", "tet", "mve-box", "mve-ball"};
  std::vector<int> sizes = {4, 8, 16};
  if (const char* s = std::getenv("NARIS_BENCH_SIZES")) {
    sizes.clear();
    std::stringstream in(s);
    for (std::string item; std::getline(in, item, ',');) sizes.push_back(std::stoi(item));
  }
  std::printf(
      "Steady Ethier–Steinman flow on [−1,1]³ (ball: radius 0.95), exact Dirichlet velocity\n");
  std::printf("%-9s %6s %7s %8s %8s %7s %8s %11s %6s %11s %6s\n", "mesh", "nu", "h", "cells",
              "nodes", "Picard", "time s", "L2 u", "rate", "L2 p", "rate");
  for (const auto& kind : kinds)
    for (const double nu : {1.0, 0.01}) {
      double last_h = 0, last_u = 0, last_p = 0;
      for (int n : sizes) {
        const HybridMesh mesh = testing::convergence_mesh(kind, n);
        const ns::BodyForce force = [nu](const Eigen::Vector3d& x) -> Eigen::Vector3d {
          return nu * testing::kBeltramiD * testing::kBeltramiD * testing::beltrami(x);
        };
        nonlinear::NonlinearReport report;
        nonlinear::NonlinearOptions options;
        options.tolerance = 1e-9;
        Stopwatch clock;
        const ns::FlowField f = nonlinear::solve_navier_stokes(
            mesh,
            ns::FlowProblem{
                1.0 / nu, force,
                testing::exact_on_boundary(mesh, testing::beltrami, testing::beltrami_pressure)},
            options, &report);
        const double seconds = clock.seconds();
        const auto e = testing::l2_errors(mesh, f, testing::beltrami, testing::beltrami_pressure);
        const double h = 2.0 / n;
        std::printf("%-9s %6g %7.4f %8zu %8zu %7d %8.2f %11.3e ", kind.c_str(), nu, h,
                    mesh.cell_count(), mesh.nodes.size(), report.iterations, seconds, e.velocity);
        if (last_h > 0)
          std::printf("%6.2f %11.3e %6.2f%s\n",
                      std::log(last_u / e.velocity) / std::log(last_h / h), e.pressure,
                      std::log(last_p / e.pressure) / std::log(last_h / h),
                      report.converged ? "" : "  (not converged)");
        else
          std::printf("%6s %11.3e %6s%s\n", "", e.pressure, "",
                      report.converged ? "" : "  (not converged)");
        std::fflush(stdout);
        last_h = h, last_u = e.velocity, last_p = e.pressure;
      }
    }
}
