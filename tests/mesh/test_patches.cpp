// Cut planes and patches: areas, perimeters and hydraulic diameters against circles, oblique
// cuts lying exactly on their plane, and carving named regions out of the wall.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/error.h"
#include "mesh/patches/patches.h"
#include "mesh/quality/check.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

using testing::ArrayField;

// A ball of radius r (voxels) in an n³ grid with unit spacing, as a distance field.
ArrayField ball(int n, double r, Eigen::Vector3d centre) {
  ArrayField f(n, n, n);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        f.at(i, j, k) = static_cast<float>(r - (Eigen::Vector3d(i, j, k) - centre).norm());
  return f;
}

const PatchReport& find(const std::vector<PatchReport>& r, const std::string& name) {
  for (const auto& p : r)
    if (p.name == name) return p;
  throw std::runtime_error("no patch " + name);
}

HybridMesh mesh_with_cuts(const mve::FieldSource& field, const std::vector<Cut>& cuts,
                          const std::vector<Region>& regions = {}) {
  mve::MveOptions o = testing::quiet_options();
  const PreparedCuts prepared = prepare_cuts(field, cuts, o);
  HybridMesh m = mve::march_volume_elements(field, o);
  finish_patches(m, field, cuts, prepared, regions, o.wall_patch);
  return m;
}

TEST(CutPlane, ParsesIndexAndPhysicalForms) {
  const CutPlane a = parse_cut_plane("j=19");
  EXPECT_TRUE(a.index_plane);
  EXPECT_EQ(a.axis, 1);
  EXPECT_EQ(a.index, 19.0);
  const CutPlane b = parse_cut_plane("p=1,2.5,-3;n=0,0,2");
  EXPECT_FALSE(b.index_plane);
  EXPECT_EQ(b.point, Eigen::Vector3d(1, 2.5, -3));
  EXPECT_EQ(b.normal, Eigen::Vector3d(0, 0, 1));
  EXPECT_THROW(parse_cut_plane("x=3"), Error);
  EXPECT_THROW(parse_cut_plane("p=1,2;n=0,0,1"), Error);
  EXPECT_THROW(parse_cut_plane("p=1,2,3;n=0,0,0"), Error);
  EXPECT_THROW(parse_cut_plane("j=abc"), Error);
}

TEST(Region, ParsesBoxesAndSpheres) {
  const Region b = parse_region("olfactory:box=1,2,3,0,5,6");
  EXPECT_EQ(b.name, "olfactory");
  EXPECT_TRUE(b.contains(Eigen::Vector3d(0.5, 3, 4)));
  EXPECT_FALSE(b.contains(Eigen::Vector3d(2, 3, 4)));
  const Region s = parse_region("cylinder:sphere=0,0,0,2");
  EXPECT_TRUE(s.contains(Eigen::Vector3d(1, 1, 1)));
  EXPECT_THROW(parse_region("bad:cone=1,2,3"), Error);
  EXPECT_THROW(parse_region("s:sphere=0,0,0,-1"), Error);
}

// A straight pipe along k that touches both ends of the grid is closed by its end faces.
TEST(Patches, PipeEndsGiveCircularInletAndOutlet) {
  const int n = 44;
  const double r = 18.0;
  ArrayField f(n, n, 30);
  for (int k = 0; k < 30; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        f.at(i, j, k) = static_cast<float>(r - std::hypot(i - 21.3, j - 21.7));
  const HybridMesh m =
      mesh_with_cuts(f, {{"inlet", parse_cut_plane("k=0")}, {"outlet", parse_cut_plane("k=29")}});
  EXPECT_TRUE(check_mesh(m).valid());
  const auto report = patch_report(m);
  for (const char* name : {"inlet", "outlet"}) {
    const auto& p = find(report, name);
    EXPECT_NEAR(p.area, std::numbers::pi * r * r, 0.01 * std::numbers::pi * r * r) << name;
    EXPECT_NEAR(p.perimeter, 2 * std::numbers::pi * r, 0.02 * 2 * std::numbers::pi * r) << name;
    EXPECT_NEAR(p.hydraulic_diameter(), 2 * r, 0.03 * 2 * r) << name;
  }
}

TEST(Patches, IndexPlaneCropsTheSideAwayFromTheObject) {
  const ArrayField f = ball(24, 9.0, {11.7, 12.2, 11.4});
  // The ball's centre is at k ≈ 11.4: the plane k = 11 keeps the upper half.
  const HybridMesh m = mesh_with_cuts(f, {{"inlet", parse_cut_plane("k=11")}});
  EXPECT_TRUE(check_mesh(m).valid());
  const auto report = patch_report(m);
  const auto& inlet = find(report, "inlet");
  const double expected = std::numbers::pi * (81.0 - 0.4 * 0.4);
  EXPECT_NEAR(inlet.area, expected, 0.02 * expected);
  for (const auto& x : m.nodes) EXPECT_GE(x[2], 11.0 - 1e-12);
}

// Oblique cuts put their faces exactly on the plane. At the rim, cubes cut by both the plane
// and the object give faces that belong to neither exactly; they count as wall, so the cut's
// area converges at first order in the voxel size.
TEST(Patches, ObliquePlaneFacesLieOnThePlaneAndConverge) {
  const Eigen::Vector3d c(12.6, 12.3, 12.8), n = Eigen::Vector3d(1, 1, 0.5).normalized();
  std::vector<double> errors;
  for (double h : {1.0, 0.5}) {
    const int size = static_cast<int>(26 / h);
    ArrayField f(size, size, size);
    f.mutable_frame().spacing = Eigen::Vector3d::Constant(h);
    for (int k = 0; k < size; ++k)
      for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i)
          f.at(i, j, k) = static_cast<float>(10.0 - (Eigen::Vector3d(i, j, k) * h - c).norm());
    const HybridMesh m =
        mesh_with_cuts(f, {{"outlet", parse_cut_plane("p=12.6,12.3,12.8;n=1,1,0.5")}});
    const MeshCheck check = check_mesh(m);
    ASSERT_TRUE(check.valid()) << check.describe();
    const int id = m.patch_id("outlet");
    for (std::size_t t = 0; t < m.boundary_tris.size(); ++t) {
      if (m.boundary_tri_patch[t] != id) continue;
      for (NodeId v : m.boundary_tris[t]) ASSERT_NEAR(n.dot(m.nodes[v] - c), 0.0, 1e-9);
    }
    const double exact = std::numbers::pi * 100.0;
    errors.push_back((exact - find(patch_report(m), "outlet").area) / exact);
  }
  EXPECT_GT(errors[0], 0.0);
  EXPECT_LT(errors[0], 0.2);
  EXPECT_GT(std::log2(errors[0] / errors[1]), 0.9);
}

// An inlet and an outlet keep what lies between them even when the object's centroid is beyond
// both: a pipe along k into a large ball, cut across the pipe alone (an index plane and an
// oblique one).
TEST(Patches, InletAndOutletKeepThePartBetweenThem) {
  const int n = 40;
  const double r = 5.0;
  ArrayField f(n, n, n);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double pipe = r - std::hypot(i - 19.6, j - 20.3);
        const double ball =
            13.0 - (Eigen::Vector3d(i, j, k) - Eigen::Vector3d(19.6, 20.3, 26.0)).norm();
        f.at(i, j, k) = static_cast<float>(std::max(pipe, ball));
      }
  const Eigen::Vector3d tilt = Eigen::Vector3d(0.0, 0.1, 1.0).normalized();
  const HybridMesh m = mesh_with_cuts(f, {{"inlet", parse_cut_plane("k=2")},
                                          {"outlet", parse_cut_plane("p=19.6,20.3,9;n=0,0.1,1")}});
  const MeshCheck check = check_mesh(m);
  ASSERT_TRUE(check.valid()) << check.describe();
  const auto report = patch_report(m);
  const double circle = std::numbers::pi * r * r;
  EXPECT_NEAR(find(report, "inlet").area, circle, 0.03 * circle);
  // The tilted plane cuts the pipe in an ellipse of area πr²/cos θ, less the rim cells that
  // count as wall (first order in the voxel size: Patches.ObliquePlaneFacesLieOnThePlane…).
  const double outlet = find(report, "outlet").area;
  EXPECT_GT(outlet, 0.5 * circle);
  EXPECT_LT(outlet, 1.01 * circle / tilt[2]);
  for (const auto& x : m.nodes) {
    EXPECT_GE(x[2], 2.0 - 1e-12);
    EXPECT_LE(tilt.dot(x - Eigen::Vector3d(19.6, 20.3, 9.0)), 1e-9);
  }
  // Two planes in one voxel plane have nothing between them.
  EXPECT_THROW(mesh_with_cuts(f, {{"inlet", parse_cut_plane("k=4")},
                                  {"outlet", parse_cut_plane("p=0,0,4.2;n=0,0,1")}}),
               Error);
}

TEST(Patches, PlaneThatMissesTheObjectIsAnError) {
  const ArrayField f = ball(24, 6.0, {11.5, 11.5, 11.5});
  try {
    mesh_with_cuts(f, {{"inlet", parse_cut_plane("k=2")}});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not cut the object"), std::string::npos) << e.what();
  }
}

TEST(Patches, RegionsAreCarvedOutOfTheWall) {
  const ArrayField f = ball(24, 9.0, {11.5, 11.5, 11.5});
  const HybridMesh m = mesh_with_cuts(f, {}, {parse_region("cap:box=-1,-1,17,30,30,30")});
  EXPECT_TRUE(check_mesh(m).valid());
  const auto report = patch_report(m);
  const auto& cap = find(report, "cap");
  // The spherical cap above z = 17 (h = 3.5 from the top): area 2πRh.
  EXPECT_NEAR(cap.area, 2 * std::numbers::pi * 9.0 * 3.5, 0.06 * 2 * std::numbers::pi * 9.0 * 3.5);
  EXPECT_NEAR(cap.area + find(report, "wall").area, 4 * std::numbers::pi * 81.0,
              0.02 * 4 * std::numbers::pi * 81.0);
  EXPECT_THROW(mesh_with_cuts(f, {}, {parse_region("nowhere:sphere=100,100,100,1")}), Error);
}

}  // namespace
}  // namespace naris
