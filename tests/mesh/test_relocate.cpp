// Node relocation keeps the mesh valid, raises the worst cell, keeps wall nodes on the surface
// and leaves the interior hexahedra as they were.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.h"
#include "mesh/mve/mve.h"
#include "mesh/pipeline/mesh_job.h"
#include "mesh/quality/check.h"
#include "mesh/quality/improve.h"
#include "mesh/quality/relocate.h"

namespace naris {
namespace {

TEST(Relocate, SphereSignedDistanceImprovesAndStaysOnTheSurface) {
  const int n = 30;
  const double radius = 11.3;
  const Eigen::Vector3d centre(14.37, 14.71, 14.13);
  Volume<float> volume;
  volume.frame.dims = {n, n, n};
  volume.values.resize(volume.frame.voxel_count());
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        volume.at(i, j, k) =
            static_cast<float>(radius - (Eigen::Vector3d(i, j, k) - centre).norm());
  const mve::VolumeField field(volume, InsideRule::above, 0.0);
  mve::MveOptions options;
  options.keep_largest_component = false;
  HybridMesh mesh = mve::march_volume_elements(field, options);
  std::vector<std::int64_t> unchanged_from;
  improve_mesh(mesh, 1.0, ImproveOptions{}, &unchanged_from);
  const HybridMesh before = mesh;
  auto farthest_wall_node = [&](const HybridMesh& m) {
    double d = 0.0;
    for (const auto& t : m.boundary_tris)
      for (NodeId v : t) d = std::max(d, std::abs((m.nodes[v] - centre).norm() - radius));
    return d;
  };
  const double volume_before = mesh_volume(mesh);

  const std::vector<bool> on_surface(mesh.patch_names.size(), true);
  const RelocateStats s =
      relocate_nodes(mesh, &field, on_surface, RelocateOptions{}, &unchanged_from);
  std::printf(
      "[ info ] cells below target %zu → %zu, worst score %.4f → %.4f, %zu nodes moved, "
      "%zu slivers removed\n",
      s.cells_below_before, s.cells_below_after, s.worst_before, s.worst_after, s.nodes_moved,
      s.slivers_removed);
  const MeshCheck check = check_mesh(mesh);
  ASSERT_TRUE(check.valid()) << check.describe();
  ASSERT_EQ(unchanged_from.size(), mesh.cell_count());
  EXPECT_GT(s.nodes_moved, 0u);
  EXPECT_GT(s.worst_after, s.worst_before);
  EXPECT_LT(s.cells_below_after, s.cells_below_before);
  // Wall nodes slide on the trilinear interpolant's level zero, where MVE put them: no farther
  // from the sphere than before (plus rounding), and on that level zero to rounding.
  std::printf(
      "[ info ] farthest wall node from the sphere %.4f before, %.4f after; largest "
      "offset from the level zero %.2e\n",
      farthest_wall_node(before), farthest_wall_node(mesh), s.largest_surface_offset);
  EXPECT_LE(farthest_wall_node(mesh), farthest_wall_node(before) + 1e-9);
  EXPECT_LT(s.largest_surface_offset, 1e-9);
  EXPECT_NEAR(mesh_volume(mesh), volume_before, 1e-3 * volume_before);
  // A hexahedron whose nodes are used by hexahedra only is still a unit cube on the lattice
  // (node numbers change when removed slivers take nodes along, so compare with the lattice).
  std::vector<char> other(mesh.nodes.size(), 0);
  for (const auto& t : mesh.tets)
    for (NodeId v : t) other[v] = 1;
  for (const auto& p : mesh.pyramids)
    for (NodeId v : p) other[v] = 1;
  const std::array<Eigen::Vector3d, 8> corner = {
      Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 0),
      Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 1),
      Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(0, 1, 1)};
  std::size_t interior = 0;
  for (const auto& h : mesh.hexes) {
    if (std::any_of(h.begin(), h.end(), [&](NodeId v) { return other[v]; })) continue;
    ++interior;
    const Eigen::Vector3d origin = mesh.nodes[h[0]];
    EXPECT_LT((origin - origin.array().round().matrix()).norm(), 1e-12);
    for (int k = 0; k < 8; ++k) EXPECT_LT((mesh.nodes[h[k]] - origin - corner[k]).norm(), 1e-12);
  }
  EXPECT_GT(interior, 0u);
  EXPECT_EQ(mesh.hexes.size(), before.hexes.size());
}

TEST(Relocate, WithoutTheImprovementIsRefused) {
  MeshJob job;
  job.input = "absent.nrrd";
  job.improve = false;
  job.relocate = true;
  try {
    run_mesh_job(job);
    ADD_FAILURE() << "relocation without the improvement was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--no-improve"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace naris
