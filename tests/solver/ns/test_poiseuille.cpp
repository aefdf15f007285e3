// Hagen–Poiseuille flow in a straight pipe meshed by MVE from a sampled cylinder, 20 voxels
// across, with the fully developed inlet profile, no slip on the wall and the traction-free
// outlet: the pressure gradient in the developed region against 8πνQ/A² and the centreline
// speed against twice the mean (VERIFICATION.md §2), at a low Reynolds number and at 610;
// inlet and outlet fluxes agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>

#include "core/error.h"
#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/ns/inlet_expression.h"
#include "solver/ns/patch_integrals.h"
#include "solver/ns/reaction_force.h"
#include "solver/ns/wall_stress.h"
#include "solver/parallel/partition.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/meshes.h"

namespace naris::ns {
namespace {

using nonlinear::NonlinearOptions;
using nonlinear::NonlinearReport;
using nonlinear::solve_navier_stokes;

// D = 1 along z from 0 to `length`, h = D/20; the pipe leaves the grid through k = min (inlet)
// and k = max (outlet).
HybridMesh pipe(double length) {
  const double h = 1.0 / 20.0;
  mve::MveOptions options;
  options.side_patch[4] = "inlet";
  options.side_patch[5] = "outlet";
  return testing::mve_mesh_box(
      [](const Eigen::Vector3d& x) { return 0.5 - std::hypot(x[0] - 0.013, x[1] + 0.007); },
      {-0.6, -0.6, 0.0}, {0.6, 0.6, length}, h, options);
}

// Area-weighted means over the wall faces of the developed region, 1 ≤ z ≤ 3 (length 2), of
// a per-face shear (boundary triangles first, as wall_stress.h orders them).
struct DevelopedShear {
  double magnitude = 0.0, axial = 0.0, wall_area = 0.0;
};
DevelopedShear developed_shear(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& shear) {
  const int wall = mesh.patch_id("wall");
  DevelopedShear d;
  for (std::size_t t = 0; t < mesh.boundary_tris.size(); ++t) {
    if (mesh.boundary_tri_patch[t] != wall) continue;
    const auto& v = mesh.boundary_tris[t];
    const Eigen::Vector3d c = (mesh.nodes[v[0]] + mesh.nodes[v[1]] + mesh.nodes[v[2]]) / 3.0;
    if (c[2] < 1.0 || c[2] > 3.0) continue;
    const double a = polygon_area(mesh, v);
    d.magnitude += a * shear[t].norm();
    d.axial += a * shear[t][2];
    d.wall_area += a;
  }
  d.magnitude /= d.wall_area;
  d.axial /= d.wall_area;
  return d;
}

void check_poiseuille(double re) {
  const double length = 4.0, nu = 1.0 / re;
  const HybridMesh mesh = pipe(length);
  InletSummary inlet;
  const DirichletConditions bc = airflow_conditions(mesh, InletProfile::developed, 1.0, &inlet);
  NonlinearReport report;
  const FlowField f = solve_navier_stokes(mesh, ns::FlowProblem{1.0 / nu, {}, bc}, {}, &report);
  ASSERT_TRUE(report.converged) << "Re " << re;
  const double q = inlet.flux, area = inlet.area;
  // Pressure gradient: least squares p = p0 + G z over the nodes of the middle half.
  double sz = 0, sp = 0, szz = 0, szp = 0, n = 0, centre = 0, centre_n = 0;
  for (std::size_t k = 0; k < mesh.nodes.size(); ++k) {
    const Eigen::Vector3d& x = mesh.nodes[k];
    if (x[2] < 1.0 || x[2] > 3.0) continue;
    sz += x[2], sp += f.pressure[k], szz += x[2] * x[2], szp += x[2] * f.pressure[k], ++n;
    if (std::hypot(x[0] - 0.013, x[1] + 0.007) < 0.04) centre += f.velocity[k][2], ++centre_n;
  }
  const double gradient = -(n * szp - sz * sp) / (n * szz - sz * sz);
  const double hagen_poiseuille = 8.0 * std::numbers::pi * nu * q / (area * area);
  const double u_max = centre / centre_n, u_mean = q / area;
  const double in = -patch_flux(mesh, f.velocity, mesh.patch_id("inlet"));
  const double out = patch_flux(mesh, f.velocity, mesh.patch_id("outlet"));
  std::printf(
      "[ info ] Re %g: %zu cells, %d Picard steps; -dp/dz %.5f vs Hagen-Poiseuille %.5f (%.2f%%); "
      "centreline %.4f vs 2 x mean %.4f (%.2f%%); flux in %.8f out %.8f\n",
      re, mesh.cell_count(), report.iterations, gradient, hagen_poiseuille,
      100 * (gradient / hagen_poiseuille - 1), u_max, 2 * u_mean, 100 * (u_max / (2 * u_mean) - 1),
      in, out);
  EXPECT_NEAR(gradient, hagen_poiseuille, 0.02 * hagen_poiseuille);
  EXPECT_NEAR(u_max, 2 * u_mean, 0.02 * 2 * u_mean);
  // Wall shear stress 4νŪ/R: the cell gradient next to the wall is a secant of the parabola,
  // first order in h (at h = R/10 about 5 % low), so this checks magnitude and direction.
  const WallStress stress = wall_stress(mesh, f, re);
  const int wall = mesh.patch_id("wall");
  const DevelopedShear cells = developed_shear(mesh, stress.shear);
  const double tau = cells.magnitude,
               exact_tau = 4.0 * nu * u_mean / std::sqrt(area / std::numbers::pi);
  std::printf("[ info ] Re %g: wall shear %.5f vs 4 nu U/R %.5f (%.2f%%)\n", re, tau, exact_tau,
              100 * (tau / exact_tau - 1));
  EXPECT_NEAR(tau, exact_tau, 0.06 * exact_tau);
  EXPECT_GT(cells.axial, 0.99 * tau);  // along the flow
  EXPECT_NEAR(out, in, 1e-6 * in);
  EXPECT_NEAR(in, q, 1e-9 * q);

  // The consistent (reaction) force: in developed flow the wall carries the drop of the mean
  // pressure times the section, and the patches' forces balance the momentum fluxes.
  const Reactions reactions =
      reaction_forces(mesh, parallel::whole_numbering(mesh.nodes.size()), f,
                      FlowProblem{re, {}, bc}, airflow_patch_kinds(mesh), PETSC_COMM_WORLD);
  const std::vector<Eigen::Vector3d>& forces = reactions.patches;
  const int inlet_id = mesh.patch_id("inlet"), outlet_id = mesh.patch_id("outlet");
  const PatchIntegral p_in = patch_integral(mesh, f.pressure, inlet_id),
                      p_out = patch_integral(mesh, f.pressure, outlet_id);
  const double drop_force = (p_in.integral / p_in.area - p_out.integral / p_out.area) * area;
  const Eigen::Vector3d& on_wall = forces[static_cast<std::size_t>(wall)];
  const Eigen::Vector3d surface = stress.patches[static_cast<std::size_t>(wall)].pressure +
                                  stress.patches[static_cast<std::size_t>(wall)].viscous;
  Eigen::Vector3d balance = patch_momentum_flux(mesh, f.velocity, inlet_id) +
                            patch_momentum_flux(mesh, f.velocity, outlet_id);
  for (const auto& force : forces) balance += force;
  std::printf(
      "[ info ] Re %g: wall force %.6f (surface integral %.6f) vs dp A %.6f (%.3f%%); momentum "
      "balance %.2e of the wall force\n",
      re, on_wall[2], surface[2], drop_force, 100 * (on_wall[2] / drop_force - 1),
      balance.norm() / on_wall.norm());
  EXPECT_NEAR(on_wall[2], drop_force, 0.01 * drop_force);
  EXPECT_LT(std::hypot(on_wall[0], on_wall[1]), 1e-3 * on_wall[2]);
  EXPECT_LT(balance.norm(), 1e-3 * on_wall.norm());
  // The wall shear of the consistent traction in the developed region: there the wall of any
  // section carries the pressure gradient, τ_w P = A (−dp/dz), with the meshed section's A and
  // perimeter P (the wall's area over its length) — exact for the faceted pipe, where 4νU/R is
  // not.
  const DevelopedShear consistent =
      developed_shear(mesh, consistent_wall_shear(mesh, reactions, airflow_patch_kinds(mesh)));
  const double consistent_shear = consistent.magnitude;
  const double section_balance = area / (consistent.wall_area / 2.0) * gradient;
  std::printf(
      "[ info ] Re %g: consistent wall shear %.5f vs A/P (-dp/dz) %.5f (%.2f%%), 4 nu U/R %.5f "
      "(%.2f%%)\n",
      re, consistent_shear, section_balance, 100 * (consistent_shear / section_balance - 1),
      exact_tau, 100 * (consistent_shear / exact_tau - 1));
  EXPECT_NEAR(consistent_shear, section_balance, 0.01 * section_balance);
  EXPECT_GT(consistent.axial, 0.99 * consistent_shear);
}

TEST(Poiseuille, PressureDropAndCentrelineAtLowReynolds) {
  check_poiseuille(1.0);
}
TEST(Poiseuille, PressureDropAndCentrelineAtRe610) {
  check_poiseuille(610.0);
}

TEST(Poiseuille, MissingPatchesAreClearErrors) {
  const HybridMesh box = testing::box_hex(3);
  EXPECT_THROW(airflow_conditions(box, InletProfile::uniform, 1.0), Error);
}

// The Hagen–Poiseuille parabola typed as an expression of r lands on the inlet nodes as
// written (scaled to the mean speed), and agrees with the developed profile from the Poisson
// solve on the inlet face to its discretization error.
TEST(InletProfile, ExpressionOfThePipeParabolaMatchesTheDevelopedProfile) {
  const HybridMesh mesh = pipe(1.0);
  InletSummary inlet, developed_inlet;
  const InletExpression parabola("1 - (r / 0.5)^2");
  const DirichletConditions typed =
      airflow_conditions(mesh, InletProfile::expression, 1.0, &inlet,
                         [&](const Eigen::Vector3d& x, double r) { return parabola(x, r); });
  const DirichletConditions developed =
      airflow_conditions(mesh, InletProfile::developed, 1.0, &developed_inlet);
  EXPECT_NEAR(inlet.flux, inlet.area, 1e-12 * inlet.area);  // mean speed 1
  EXPECT_NEAR((inlet.centroid - Eigen::Vector3d(0.013, -0.007, 0.0)).norm(), 0.0, 1e-3);
  ASSERT_EQ(typed.nodes, developed.nodes);
  double scale = 0.0, largest_difference = 0.0, ratio_spread = 0.0;
  std::vector<double> ratios;
  for (std::size_t k = 0; k < typed.nodes.size(); ++k) {
    const Eigen::Vector3d& x = mesh.nodes[static_cast<std::size_t>(typed.nodes[k])];
    const double r = (x - inlet.centroid).norm(), exact = 1.0 - (r / 0.5) * (r / 0.5);
    const double value = typed.values[k].dot(inlet.normal);
    scale = std::max(scale, value);
    largest_difference =
        std::max(largest_difference, (typed.values[k] - developed.values[k]).norm());
    if (x[2] == 0.0 && exact > 0.1 && value > 0.0) ratios.push_back(value / exact);
  }
  ASSERT_GT(ratios.size(), 50u);
  const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
  ratio_spread = *hi / *lo - 1.0;
  std::printf("[ info ] expression vs developed: max difference %.4f of a peak %.4f\n",
              largest_difference, scale);
  EXPECT_LT(ratio_spread, 1e-12);  // one factor: the flux scaling
  EXPECT_LT(largest_difference, 0.05 * scale);
}

TEST(InletProfile, BadExpressionsAreClearErrors) {
  const HybridMesh mesh = pipe(1.0);
  auto conditions = [&](const std::string& text) {
    const InletExpression e(text);
    return airflow_conditions(mesh, InletProfile::expression, 1.0, nullptr,
                              [&](const Eigen::Vector3d& x, double r) { return e(x, r); });
  };
  auto message = [&](const std::function<void()>& run) {
    try {
      run();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { InletExpression("1 - (r/2"); }).find("inlet expression"),
            std::string::npos);
  EXPECT_NE(message([&] { InletExpression("1 - q"); }).find("q"), std::string::npos);
  EXPECT_NE(message([&] { InletExpression(" "); }).find("empty"), std::string::npos);
  EXPECT_NE(message([&] { conditions("r - 0.2"); }).find("not negative"), std::string::npos);
  EXPECT_NE(message([&] { conditions("sqrt(r - 1)"); }).find("finite"), std::string::npos);
  EXPECT_NE(message([&] { conditions("0"); }).find("zero on the whole inlet"), std::string::npos);
  // Variables in the mesh frame: 2x + y² at a point.
  const InletExpression e("2*x + y^2 + 0*z + r");
  EXPECT_DOUBLE_EQ(e(Eigen::Vector3d(1.5, -3.0, 7.0), 0.25), 3.0 + 9.0 + 0.25);
}

}  // namespace
}  // namespace naris::ns
