// Cross-sections against exact geometry (planar faces: the area to round-off; a sampled
// cylinder: area and smoothed perimeter within 1 %) and against flows solved by naris:
// Hagen–Poiseuille in an MVE pipe (the flux of every plane equals the inlet's; the maximum
// axial velocity is twice the mean) and an abrupt contraction, where the mass the method
// conserves is that of the nodal plus the fine-scale velocity.
#include <gtest/gtest.h>
#include <vtkCell.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>

#include "core/error.h"
#include "postproc/planes/outline.h"
#include "postproc/planes/sections.h"
#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/ns/oseen_element.h"
#include "solver/ns/patch_integrals.h"
#include "solver/ns/subgrid_velocity.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/meshes.h"

namespace naris::planes {
namespace {

using std::numbers::pi;
using Vec3 = Eigen::Vector3d;

SectionPlane plane(const Vec3& point, const Vec3& normal) {
  return {point, normal.normalized(), "test", 0.0, false};
}

std::vector<Vec3> uniform(const HybridMesh& m, const Vec3& u) {
  return std::vector<Vec3>(m.nodes.size(), u);
}

// With and without a fine-scale velocity per cell (VTK's cutter may take another path when the
// grid has cell data): the flux of a uniform u + u' is (u + u')·n times the area.
TEST(Sections, PlanarFacesGiveTheExactArea) {
  for (const HybridMesh& m : {testing::box_hex(6), testing::box_tet(5)})
    for (const Vec3& fine : {Vec3(0, 0, 0), Vec3(0.05, 0.02, -0.3)}) {
      const std::vector<Vec3> u = uniform(m, Vec3(0.2, -0.1, 1.5));
      const std::vector<Vec3> sub =
          fine.isZero() ? std::vector<Vec3>{} : std::vector<Vec3>(m.cell_count(), fine);
      const SectionCutter cutter(m, u, sub, voxel_size(m));
      // Through cells, along a node layer, and oblique: a regular hexagon of side √2.
      for (const auto& [p, area] : {std::pair{plane({0, 0, 0.3141}, {0, 0, 1}), 4.0},
                                    std::pair{plane({0, 0, 1.0 / 3.0}, {0, 0, 1}), 4.0},
                                    std::pair{plane({0, 0, 0}, {1, 1, 1}), 3.0 * std::sqrt(3.0)}}) {
        const Section s = cutter.cut(p);
        ASSERT_EQ(s.pieces.size(), 1u);
        EXPECT_NEAR(s.whole.area / area - 1.0, 0.0, 1e-12) << p.normal.transpose();
        // A uniform velocity: the flux is u·n times the area, the mean axial velocity u·n.
        const double un = (Vec3(0.2, -0.1, 1.5) + fine).dot(p.normal);
        EXPECT_NEAR(s.whole.flux / (un * area * 1e-6) - 1.0, 0.0, 1e-12);
        EXPECT_NEAR(s.whole.mean_axial / un - 1.0, 0.0, 1e-12);
        EXPECT_NEAR(s.whole.max_speed, Vec3(0.2, -0.1, 1.5).norm(), 1e-12);
      }
    }
}

TEST(Sections, APlaneOutsideTheMeshIsAnError) {
  const HybridMesh m = testing::box_hex(3);
  const std::vector<Vec3> u = uniform(m, Vec3::UnitZ());
  const SectionCutter cutter(m, u, {}, 0.5);
  EXPECT_THROW(cutter.cut(plane({0, 0, 1.5}, {0, 0, 1})), Error);
}

TEST(Sections, TwoPiecesAreMeasuredApartLargestFirst) {
  // Two tubes of radii 0.5 and 0.3 side by side.
  const auto inside = [](const Vec3& x) {
    return std::max(0.5 - std::hypot(x[0] + 0.8, x[1]), 0.3 - std::hypot(x[0] - 0.6, x[1]));
  };
  mve::MveOptions options;
  options.keep_largest_component = false;
  const HybridMesh m =
      testing::mve_mesh_box(inside, {-1.5, -0.7, -0.2}, {1.1, 0.7, 0.2}, 0.05, options);
  const std::vector<Vec3> u = uniform(m, Vec3::UnitZ());
  const Section s = SectionCutter(m, u, {}, 0.05).cut(plane({0, 0, 0.01}, {0, 0, 1}));
  ASSERT_EQ(s.pieces.size(), 2u);
  EXPECT_NEAR(s.pieces[0].area / (pi * 0.25), 1.0, 0.02);
  EXPECT_NEAR(s.pieces[1].area / (pi * 0.09), 1.0, 0.03);
  EXPECT_NEAR(s.pieces[0].centroid[0], -0.8, 0.01);
  EXPECT_NEAR(s.pieces[1].centroid[0], 0.6, 0.01);
  // The surface's piece array names the same pieces: the area of its cells per piece.
  double area[3] = {0.0, 0.0, 0.0};
  vtkDataArray* piece = s.surface->GetCellData()->GetArray("piece");
  ASSERT_NE(piece, nullptr);
  for (vtkIdType c = 0; c < s.surface->GetNumberOfCells(); ++c) {
    vtkCell* cell = s.surface->GetCell(c);
    if (cell->GetNumberOfPoints() != 3) continue;
    double a[3], b[3], d[3];
    s.surface->GetPoint(cell->GetPointId(0), a);
    s.surface->GetPoint(cell->GetPointId(1), b);
    s.surface->GetPoint(cell->GetPointId(2), d);
    const Vec3 ab = Vec3(b[0], b[1], b[2]) - Vec3(a[0], a[1], a[2]),
               ad = Vec3(d[0], d[1], d[2]) - Vec3(a[0], a[1], a[2]);
    area[static_cast<int>(piece->GetTuple1(c))] += 0.5 * ab.cross(ad).norm();
  }
  EXPECT_NEAR(area[1] / s.pieces[0].area, 1.0, 1e-12);
  EXPECT_NEAR(area[2] / s.pieces[1].area, 1.0, 1e-12);
}

// A region box over half of a box's section takes exactly half of a uniform flux.
TEST(Sections, ARegionBoxTakesItsShareOfTheFlux) {
  const HybridMesh m = testing::box_hex(6);
  const std::vector<Vec3> u = uniform(m, Vec3(0.0, 0.0, 2.0));
  const RegionBox half{0, Vec3(-2, -2, -2), Vec3(0.0, 2, 2)}, none{0, Vec3(5, 5, 5), Vec3(6, 6, 6)};
  const Section s =
      SectionCutter(m, u, {}, 0.5).cut(plane({0, 0, 0.3141}, {0, 0, 1}), {half, none});
  ASSERT_EQ(s.whole.region_flux.size(), 2u);
  EXPECT_NEAR(s.whole.region_flux[0] / s.whole.flux, 0.5, 1e-12);
  EXPECT_EQ(s.whole.region_flux[1], 0.0);
}

// A cylinder of R = 20 voxels sampled as a mask (1 inside, −1 outside, as a segmentation gives
// the mesher): the area within 1 %, the smoothed perimeter within 1 % of 2πR, while the outline
// as meshed is longer by the voxel facets.
TEST(Sections, ASampledCylinderHasItsAreaAndSmoothedPerimeter) {
  const double h = 0.05, radius = 1.0;  // 20 voxels
  const HybridMesh m = testing::mve_mesh_box(
      [&](const Vec3& x) { return std::hypot(x[0] - 0.0123, x[1] + 0.0071) < radius ? 1.0 : -1.0; },
      {-1.1, -1.1, -0.2}, {1.1, 1.1, 0.2}, h, {});
  const std::vector<Vec3> u = uniform(m, Vec3::UnitZ());
  EXPECT_NEAR(voxel_size(m), h, 1e-12);
  for (double sigma : {0.5, 0.75, 1.0, 1.5}) {
    const SectionCutter cutter(m, u, {}, sigma * voxel_size(m));
    for (double z : {0.0, 0.0137}) {  // a node layer and through cells
      const Section s = cutter.cut(plane({0, 0, z}, {0, 0, 1}));
      ASSERT_EQ(s.pieces.size(), 1u);
      const double area = s.whole.area / (pi * radius * radius) - 1.0;
      const double smoothed = s.whole.perimeter / (2 * pi * radius) - 1.0;
      const double raw = s.whole.raw_perimeter / (2 * pi * radius) - 1.0;
      std::printf(
          "cylinder R = 20 voxels, z = %g, smoothing %g voxels: area %+.4f, smoothed perimeter "
          "%+.4f, raw %+.4f\n",
          z, sigma, area, smoothed, raw);
      EXPECT_LT(std::abs(area), 0.01);
      EXPECT_GT(raw, 0.03);  // the facets of a sampled mask
      if (sigma == 1.0) {    // naris planes' default
        EXPECT_LT(std::abs(smoothed), 0.01);
      }
    }
  }
}

TEST(Outline, SmoothingKeepsACircleAndRemovesAStaircase) {
  // A circle of radius 20 as a fine polygon: smoothing shrinks it by about σ²/(2R²) = 0.3 %.
  Loop circle;
  for (int k = 0; k < 720; ++k)
    circle.emplace_back(20 * std::cos(2 * pi * k / 720), 20 * std::sin(2 * pi * k / 720), 0);
  EXPECT_NEAR(smoothed_loop_length(circle, 1.5) / (40 * pi), 1.0 - 1.5 * 1.5 / 800, 5e-4);
  // The same circle as a voxel staircase (unit voxels, moves along the axes only): its raw
  // length is 4/π too long.
  Loop stairs;
  long px = 20, py = 0;
  for (int k = 1; k <= 4000; ++k) {
    const long qx = std::lround(20 * std::cos(2 * pi * k / 4000)),
               qy = std::lround(20 * std::sin(2 * pi * k / 4000));
    if (qx == px && qy == py) continue;
    stairs.emplace_back(px, py, 0);
    if (qx != px && qy != py) stairs.emplace_back(qx, py, 0);
    px = qx, py = qy;
  }
  EXPECT_NEAR(loop_length(stairs) / (40 * pi), 4 / pi, 1e-9);
  EXPECT_NEAR(smoothed_loop_length(stairs, 1.5) / (40 * pi), 1.0, 0.01);
}

// An MVE pipe along z from 0 to `length` mm of radius `radius(z)` mm (0.1 mm voxels, inlet
// diameter D = 2 mm), its flow solved by naris at `re` on D, with U = 0.5 m/s for the SI fields.
struct PipeFlow {
  HybridMesh mesh, unit;  // in mm, and in units of D (the solver's)
  ns::FlowField field;
  std::vector<Vec3> subgrid;                  // per cell, nondimensional
  std::vector<Vec3> velocity_si, subgrid_si;  // m/s
  bool converged = false;
};
PipeFlow pipe_flow(const std::function<double(double)>& radius, double length,
                   ns::InletProfile profile, double re) {
  mve::MveOptions options;
  options.side_patch[4] = "inlet";
  options.side_patch[5] = "outlet";
  PipeFlow r;
  r.mesh = testing::mve_mesh_box(
      [&](const Vec3& x) { return radius(x[2]) - std::hypot(x[0] - 0.013, x[1] + 0.007); },
      {-1.2, -1.2, 0.0}, {1.2, 1.2, length}, 0.1, options);
  r.unit = r.mesh;
  for (auto& x : r.unit.nodes) x /= 2.0;
  const ns::DirichletConditions bc = ns::airflow_conditions(r.unit, profile, 1.0);
  nonlinear::NonlinearReport report;
  r.field = nonlinear::solve_navier_stokes(r.unit, ns::FlowProblem{re, {}, bc}, {}, &report);
  r.converged = report.converged;
  r.subgrid = ns::subgrid_velocity(r.unit, r.field, 1.0 / re, 1.0);
  for (const Vec3& v : r.field.velocity) r.velocity_si.push_back(0.5 * v);
  for (const Vec3& v : r.subgrid) r.subgrid_si.push_back(0.5 * v);
  return r;
}

// Hagen–Poiseuille in an MVE pipe (radius 1 mm, 20 voxels across, Re 10, the developed
// profile at the inlet), solved by naris.
TEST(Sections, PoiseuilleFlowKeepsItsFluxAndPeak) {
  petsc::Session session;
  const PipeFlow pipe =
      pipe_flow([](double) { return 1.0; }, 10.0, ns::InletProfile::developed, 10.0);
  ASSERT_TRUE(pipe.converged);
  const HybridMesh& m = pipe.mesh;
  const SectionCutter cutter(m, pipe.velocity_si, pipe.subgrid_si, voxel_size(m));
  const Measures inlet = cutter.patch(m.patch_id("inlet"));
  ASSERT_GT(inlet.flux, 0.0);
  for (double z : {1.0, 2.55, 5.0, 7.43, 9.0}) {
    const Section s = cutter.cut(plane({0, 0, z}, {0, 0, 1}));
    ASSERT_EQ(s.pieces.size(), 1u);
    EXPECT_NEAR(s.whole.flux / inlet.flux, 1.0, 0.005) << "z = " << z;
    EXPECT_NEAR(s.whole.max_axial / s.whole.mean_axial, 2.0, 0.04) << "z = " << z;
    EXPECT_EQ(s.whole.mean_axial, s.whole.flux / (s.whole.area * 1e-6));  // its definition
    EXPECT_NEAR(s.whole.mean_axial / 0.5, 1.0, 0.01) << "z = " << z;      // the imposed mean
  }
}

// ∫_Ω w dΩ of a nodal field's z component, cell by cell with the solver's quadrature, and of a
// cell field's (a mean per cell).
double volume_integral_z(const HybridMesh& m, const std::vector<Vec3>& nodal,
                         const std::vector<Vec3>& per_cell, double& cells_part) {
  double nodes_part = 0.0;
  cells_part = 0.0;
  std::size_t k = 0;
  auto run = [&](const auto& cells, auto element) {
    using E = decltype(element);
    constexpr int N = E::nodes;
    const auto& table = ns::ShapeTable<E>::get();
    Eigen::Matrix<double, N, 3> X;
    Eigen::Matrix<double, N, 1> w;
    for (const auto& cell : cells) {
      for (int i = 0; i < N; ++i) {
        X.row(i) = m.nodes[static_cast<std::size_t>(cell[i])].transpose();
        w[i] = nodal[static_cast<std::size_t>(cell[i])][2];
      }
      double volume = 0.0;
      for (std::size_t q = 0; q < table.points.size(); ++q) {
        const auto mapped = fem::map_to_cell<E>(X, table.shapes[q]);
        const double dv = table.points[q].weight * mapped.det_jacobian;
        nodes_part += dv * w.dot(mapped.value);
        volume += dv;
      }
      cells_part += volume * per_cell[k++][2];
    }
  };
  run(m.tets, fem::Tet4{});
  run(m.pyramids, fem::Pyr5{});
  run(m.hexes, fem::Hex8{});
  return nodes_part;
}

// An abrupt contraction (radius 1 → 0.6 mm at z = 4 mm, on a node layer; 0.1 mm voxels) at
// Re 100 on the inlet's diameter. Tested with q = z, the discrete continuity equation says
// ∫_Ω (u + u')_z dΩ = L·Q: to 1e-6, well above the solver's 1e-8 on the residual and far below
// the fine scale's share (> 1e-3). A plane's flux of u + u' is the inlet's within 0.5 % (the
// Poiseuille test's bound) two voxels or more from the step; within a voxel of it (where the
// cells' mean u' is a coarse stand-in for u' on the plane) within 2.5 %, and nearer than the
// nodal velocity's alone, which loses 4–11 % there.
TEST(Sections, AContractionConservesTheFluxOfTheNodalPlusFineScaleVelocity) {
  petsc::Session session;
  const double length = 8.0;
  const PipeFlow pipe = pipe_flow([](double z) { return z < 4.0 ? 1.0 : 0.6; }, length,
                                  ns::InletProfile::uniform, 100.0);
  ASSERT_TRUE(pipe.converged);
  const HybridMesh &m = pipe.mesh, &unit = pipe.unit;
  const ns::FlowField& f = pipe.field;
  const std::vector<Vec3>& sub = pipe.subgrid;
  ASSERT_EQ(sub.size(), m.cell_count());
  const std::vector<Vec3> sub_mm = ns::subgrid_velocity(m, f, 0.01, 2.0);
  double scale_difference = 0.0, largest = 0.0;
  for (std::size_t c = 0; c < sub.size(); ++c) {
    scale_difference = std::max(scale_difference, (sub_mm[c] - sub[c]).norm());
    largest = std::max(largest, sub[c].norm());
  }
  EXPECT_LT(scale_difference, 1e-10 * largest);  // the mesh's unit of length does not matter

  // The continuity equation tested with q = z (nondimensional).
  const double flux = ns::patch_flux(unit, f.velocity, unit.patch_id("inlet"));
  double fine = 0.0;
  const double resolved = volume_integral_z(unit, f.velocity, sub, fine);
  const double expected = -length / 2.0 * flux;  // patch_flux is outward
  EXPECT_NEAR((resolved + fine) / expected, 1.0, 1e-6);
  EXPECT_GT(std::abs(fine / expected), 1e-3);  // the fine scale carries a share

  const SectionCutter cutter(m, pipe.velocity_si, pipe.subgrid_si, voxel_size(m));
  const Measures inlet = cutter.patch(m.patch_id("inlet"));
  for (double z : {1.0, 3.0, 3.8, 3.93, 3.97, 4.03, 4.07, 4.2, 4.5, 6.0, 7.5}) {
    const Section s = cutter.cut(plane({0, 0, z}, {0, 0, 1}));
    const double total = s.whole.flux / inlet.flux, nodal = s.whole.resolved_flux / inlet.flux;
    std::printf("z %.2f: flux of u + u' %.4f, of u %.4f of the inlet's\n", z, total, nodal);
    if (std::abs(z - 4.0) > 0.15) {  // two voxels or more from the step
      EXPECT_NEAR(total, 1.0, 0.005) << "z = " << z;
    } else {
      EXPECT_NEAR(total, 1.0, 0.025) << "z = " << z;
      EXPECT_LT(std::abs(total - 1.0), std::abs(nodal - 1.0)) << "z = " << z;
    }
  }
}

}  // namespace
}  // namespace naris::planes
