// Smooth walls from labelmaps (mesh/image/smooth_label.h): a sampled sphere keeps its volume,
// a sampled cylinder's cut has the circle's perimeter (the staircase's is 5 % long), every voxel
// keeps its side, and the mesh stays conforming with the labelmap's topology.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/error.h"
#include "mesh/image/smooth_label.h"
#include "mesh/mve/mve.h"
#include "mesh/patches/patches.h"
#include "mesh/quality/check.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

Volume<std::uint8_t> sampled(int nx, int ny, int nz, auto&& inside) {
  return testing::sampled_volume<std::uint8_t>(
      nx, ny, nz, [&](int i, int j, int k) { return inside(i, j, k) ? 1 : 0; });
}

struct Meshed {
  HybridMesh mesh;
  std::vector<PatchReport> patches;
};

// The labelmap meshed as MVE meshes it: as 0/1 labels (smooth = false) or on its smooth field.
Meshed mesh_of(const Volume<std::uint8_t>& labels, bool smooth, const std::vector<Cut>& cuts) {
  Volume<float> field;
  if (smooth) {
    field = smooth_label_field(labels);
  } else {
    field.frame = labels.frame;
    field.values.assign(labels.values.begin(), labels.values.end());
  }
  const mve::VolumeField source(field, smooth ? InsideRule::above : InsideRule::label,
                                smooth ? 0.0 : 1.0);
  mve::MveOptions o = testing::quiet_options();
  const PreparedCuts prepared = prepare_cuts(source, cuts, o);
  Meshed m{mve::march_volume_elements(source, o), {}};
  finish_patches(m.mesh, source, cuts, prepared, {}, o.wall_patch);
  m.patches = patch_report(m.mesh);
  return m;
}

TEST(SmoothWalls, SphereKeepsItsVolumeAndEveryVoxelItsSide) {
  const double r = 10.0;
  const auto labels = sampled(41, 41, 41, [&](int i, int j, int k) {
    return std::hypot(i - 20.3, j - 20.1, k - 19.8) < r;
  });
  const Volume<float> field = smooth_label_field(labels);
  for (std::size_t q = 0; q < field.values.size(); ++q)
    ASSERT_EQ(field.values[q] > 0.0f, labels.values[q] == 1) << q;
  const Meshed smooth = mesh_of(labels, true, {});
  const MeshCheck check = check_mesh(smooth.mesh);
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.euler_cells, 1);
  EXPECT_EQ(check.euler_boundary, 2);
  const double exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_NEAR(testing::boundary_volume(smooth.mesh), exact, 0.01 * exact);
}

TEST(SmoothWalls, CylinderCutHasTheCirclesPerimeter) {
  const double r = 20.0;
  const auto labels =
      sampled(51, 51, 40, [&](int i, int j, int) { return std::hypot(i - 25.2, j - 24.9) < r; });
  const std::vector<Cut> cuts{{"inlet", parse_cut_plane("k=5")},
                              {"outlet", parse_cut_plane("k=30")}};
  const double circle = 2.0 * std::numbers::pi * r;
  auto inlet = [](const Meshed& m) {
    for (const auto& p : m.patches)
      if (p.name == "inlet") return p;
    throw Error("no inlet");
  };
  const PatchReport stairs = inlet(mesh_of(labels, false, cuts));
  const Meshed smooth = mesh_of(labels, true, cuts);
  EXPECT_TRUE(check_mesh(smooth.mesh).valid());
  // The chamfered staircase is ~5 % long and does not improve with resolution; the smooth wall
  // is within 2 %.
  EXPECT_GT(stairs.perimeter, 1.04 * circle);
  EXPECT_NEAR(inlet(smooth).perimeter, circle, 0.02 * circle);
  EXPECT_NEAR(inlet(smooth).area, std::numbers::pi * r * r, 0.01 * std::numbers::pi * r * r);
}

TEST(SmoothWalls, KeepsAPassageOneVoxelWide) {
  // Two boxes joined by a straight passage one voxel across: smoothing would close it; the
  // voxels keep their side, so the mesh stays one piece.
  const auto labels = sampled(40, 20, 20, [](int i, int j, int k) {
    const bool box = (i < 12 || i >= 28) && j > 3 && j < 16 && k > 3 && k < 16;
    return box || (j == 10 && k == 10);
  });
  const Meshed smooth = mesh_of(labels, true, {});
  const MeshCheck check = check_mesh(smooth.mesh);
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.euler_cells, 1) << "one ball-like piece";
  // Both boxes (12³ voxels each) are in it: the mesher would keep one if the passage closed.
  EXPECT_GT(testing::boundary_volume(smooth.mesh), 1.8 * 12 * 12 * 12);
}

TEST(SmoothWalls, RefusesAnEmptyLabelmapAndBadWidths) {
  const auto empty = sampled(8, 8, 8, [](int, int, int) { return false; });
  EXPECT_THROW(smooth_label_field(empty), Error);
  const auto ball =
      sampled(8, 8, 8, [](int i, int j, int k) { return std::hypot(i - 4, j - 4, k - 4) < 3; });
  EXPECT_THROW(smooth_label_field(ball, {.sigma = 0.0}), Error);
  EXPECT_THROW(smooth_label_field(ball, {.margin = 0.6}), Error);
}

}  // namespace
}  // namespace naris
