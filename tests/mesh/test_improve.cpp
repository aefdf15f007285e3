// Quality improvement keeps every invariant and removes the short edges it may remove.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <span>

#include "mesh/image/nasal_airway.h"
#include "mesh/image/read_volume.h"
#include "mesh/image/write_volume.h"
#include "mesh/pipeline/mesh_job.h"
#include "mesh/quality/check.h"
#include "mesh/quality/improve.h"
#include "mesh/quality/quality.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

using testing::ArrayField;

// Edges of tetrahedra shorter than `limit`; with `lattice` false, those without a hexahedron's
// node only.
std::size_t short_edges(const HybridMesh& m, double limit, bool lattice = true) {
  std::vector<char> hexahedron_node(m.nodes.size(), 0);
  if (!lattice)
    for (const auto& h : m.hexes)
      for (NodeId v : h) hexahedron_node[v] = 1;
  std::vector<std::pair<NodeId, NodeId>> e;
  for (const auto& t : m.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        if ((m.nodes[t[a]] - m.nodes[t[b]]).norm() < limit && !hexahedron_node[t[a]] &&
            !hexahedron_node[t[b]])
          e.push_back({std::min(t[a], t[b]), std::max(t[a], t[b])});
  std::sort(e.begin(), e.end());
  return static_cast<std::size_t>(std::unique(e.begin(), e.end()) - e.begin());
}

TEST(Improve, SphereKeepsInvariantsAndVolume) {
  const int n = 26;
  ArrayField f(n, n, n);
  const Eigen::Vector3d c(12.37, 12.71, 12.13);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        f.at(i, j, k) = static_cast<float>(10.3 - (Eigen::Vector3d(i, j, k) - c).norm());
  HybridMesh m = mve::march_volume_elements(f, testing::quiet_options());
  const double v0 = mesh_volume(m);
  const std::size_t cells0 = m.cell_count();
  const std::size_t before = short_edges(m, 0.2), off_lattice_before = short_edges(m, 0.2, false);
  auto farthest_boundary_node = [&]() {
    double d = 0.0;
    for (const auto& t : m.boundary_tris)
      for (NodeId v : t) d = std::max(d, std::abs((m.nodes[v] - c).norm() - 10.3));
    return d;
  };
  const double off_before = farthest_boundary_node();
  const ImproveStats s = improve_mesh(m, 1.0, ImproveOptions{});
  const MeshCheck c1 = check_mesh(m);
  ASSERT_TRUE(c1.valid()) << c1.describe();
  EXPECT_GT(s.collapsed, 0u);
  EXPECT_LT(m.cell_count(), cells0);
  // Most short edges between isopoints go; to a lattice vertex, one goes where the vertex can
  // warp onto the wall without flattening a cell.
  std::printf(
      "[ info ] short tet edges %zu → %zu, without a lattice vertex %zu → %zu; collapsed %zu, "
      "refused %zu + %zu\n",
      before, short_edges(m, 0.2), off_lattice_before, short_edges(m, 0.2, false), s.collapsed,
      s.refused_topology, s.refused_geometry);
  EXPECT_LT(short_edges(m, 0.2), before);
  EXPECT_LT(short_edges(m, 0.2, false), off_lattice_before / 2);
  EXPECT_NEAR(mesh_volume(m), v0, 0.01 * v0);
  // The wall stays on the sphere: a lattice vertex that a wall node merged into moved where that
  // node stood, and two wall nodes meet on their chord (its sagitta, 0.2² / 8r, is 5e-4 here).
  const double off_after = farthest_boundary_node();
  std::printf("[ info ] %zu lattice vertices warped; farthest wall node %.4f before, %.4f after\n",
              s.vertices_warped, off_before, off_after);
  EXPECT_GT(s.vertices_warped, 0u);
  EXPECT_LE(off_after, off_before + 5e-4);
  // Hexahedra without a boundary node are untouched; those at a warped vertex stay well shaped.
  std::vector<char> on_boundary(m.nodes.size(), 0);
  for (const auto& t : m.boundary_tris)
    for (NodeId v : t) on_boundary[v] = 1;
  const auto q = cell_quality(m);
  std::size_t warped = 0;
  for (std::size_t i = 0; i < m.hexes.size(); ++i) {
    const auto& h = m.hexes[i];
    const double jacobian = q[m.tets.size() + m.pyramids.size() + i].scaled_jacobian;
    if (std::any_of(h.begin(), h.end(), [&](NodeId v) { return on_boundary[v]; })) {
      ++warped;
      EXPECT_GT(jacobian, 0.5);
    } else {
      EXPECT_NEAR(jacobian, 1.0, 1e-9);
    }
  }
  EXPECT_GT(warped, 0u);
}

// A cut plane passing a lattice vertex closer than the isopoint margin leaves a cluster of
// isopoints a thousandth of a voxel apart around it. Collapsing it edge by edge makes cells flat
// on the way; they are the next collapse's, so the cluster goes.
TEST(Improve, AClusterWhereACutPlanePassesALatticeVertexCollapses) {
  const int n = 24;
  const Eigen::Vector2d axis(11.37, 11.71);
  const auto volume = testing::sampled_volume<float>(n, n, n, [&](int i, int j, int) {
    return (Eigen::Vector2d(i, j) - axis).norm() < 8.3 ? 1.0 : 0.0;
  });
  const mve::VolumeField field(volume, InsideRule::label, 1.0);
  mve::MveOptions options = testing::quiet_options();
  mve::ClipPlane plane;
  plane.normal = Eigen::Vector3d(0.31, 0.23, 0.92).normalized();
  const Eigen::Vector3d vertex(12, 11, 9);
  plane.offset = -plane.normal.dot(vertex) - 4e-4;  // the vertex cut off by 0.0004 voxel
  options.clip_planes.push_back(plane);
  HybridMesh m = mve::march_volume_elements(field, options);
  const std::size_t tiny_before = short_edges(m, 0.01);
  const ImproveStats s = improve_mesh(m, 1.0, ImproveOptions{});
  const MeshCheck check = check_mesh(m);
  ASSERT_TRUE(check.valid()) << check.describe();
  std::printf("[ info ] tet edges under 0.01 voxel %zu → %zu; collapsed %zu, refused %zu + %zu\n",
              tiny_before, short_edges(m, 0.01), s.collapsed, s.refused_topology,
              s.refused_geometry);
  EXPECT_GT(tiny_before, 0u);  // the cluster exists
  EXPECT_EQ(short_edges(m, 0.01), 0u);
}

// An adult CT's right cavity (NasalSeg P055; Zhang et al. 2024, CC BY 4.0) cut at its naris by
// the oblique plane the segmentation finds. Where the plane passes a lattice vertex on the wall,
// its rim (where the inlet meets the wall) gets nodes hundredths of a millimetre apart. Rim nodes
// joined by a rim edge merge along it, and a rim node merges into a hexahedron node of the
// inlet or the wall next to it (one a warp made a boundary node); only pyramids' lateral edges,
// which 3.3 never collapses, may stay that short.
TEST(Improve, AnAdultNarisRimKeepsNoShortEdge) {
  const std::filesystem::path ct_file =
      std::filesystem::path(NARIS_SHARED_DATA) / "nasalseg" / "P055_img.nrrd";
  if (!std::filesystem::exists(ct_file)) GTEST_SKIP() << "shared data absent: " << ct_file;
  const NasalAirway airway = segment_nasal_airway(read_volume(ct_file), NasalAirwayOptions{});
  const auto dir = std::filesystem::temp_directory_path() / "naris-improve-rim";
  std::filesystem::create_directories(dir);
  write_labelmap_nrrd(airway.mask, dir / "airway.nrrd");
  MeshJob job;
  job.input = dir / "airway.nrrd";
  job.inlet = airway.inlet;
  job.outlet = airway.outlet;
  const MeshJobResult r = run_mesh_job(job);
  ASSERT_TRUE(r.check.has_value());
  ASSERT_TRUE(r.check->valid()) << r.check->describe();
  const HybridMesh& m = r.mesh;
  const int wall = m.patch_id("wall"), inlet = m.patch_id("inlet");
  ASSERT_GE(inlet, 0);
  std::vector<int> side(m.nodes.size(), 0);
  for_each_boundary_face(m, [&](std::span<const NodeId> f, std::int32_t p) {
    for (NodeId v : f) side[v] |= p == wall ? 1 : p == inlet ? 2 : 4;
  });
  std::vector<char> hexahedron_node(m.nodes.size(), 0);
  for (const auto& h : m.hexes)
    for (NodeId v : h) hexahedron_node[v] = 1;
  std::set<std::pair<NodeId, NodeId>> lateral, short_rim, short_to_vertex;
  for (const auto& p : m.pyramids)
    for (int k = 0; k < 4; ++k) lateral.insert(std::minmax(p[k], p[4]));
  // Rim edges under a twentieth of a voxel; edges from the rim to a hexahedron node under the
  // collapse length (a fifth).
  const double limit = 0.05 * airway.mask.frame.spacing.minCoeff(), collapse = 4 * limit;
  for_each_boundary_face(m, [&](std::span<const NodeId> f, std::int32_t) {
    for (std::size_t k = 0; k < f.size(); ++k) {
      const auto e = std::minmax(f[k], f[(k + 1) % f.size()]);
      const double length = (m.nodes[e.first] - m.nodes[e.second]).norm();
      if (length >= collapse || lateral.count(e)) continue;
      const int a = side[e.first], b = side[e.second];
      if (a == 3 && b == 3 && length < limit) short_rim.insert(e);
      if ((a == 3 && b < 3 && hexahedron_node[e.second]) ||
          (b == 3 && a < 3 && hexahedron_node[e.first]))
        short_to_vertex.insert(e);
    }
  });
  std::printf(
      "[ info ] rim edges under %.3f mm %zu, from the rim to a hexahedron node under %.3f mm %zu; "
      "collapsed %zu, refused %zu + %zu\n",
      limit, short_rim.size(), collapse, short_to_vertex.size(), r.improvement.collapsed,
      r.improvement.refused_topology, r.improvement.refused_geometry);
  EXPECT_EQ(short_rim.size(), 0u);
  EXPECT_EQ(short_to_vertex.size(), 0u);
  // The rim stays one closed line: every rim node on exactly two of its edges (a chord's collapse
  // between two stretches of it would pinch the inlet at a node with four).
  std::map<std::pair<NodeId, NodeId>, int> edge_sides;
  for_each_boundary_face(m, [&](std::span<const NodeId> f, std::int32_t p) {
    for (std::size_t k = 0; k < f.size(); ++k)
      edge_sides[std::minmax(f[k], f[(k + 1) % f.size()])] |= p == wall ? 1 : p == inlet ? 2 : 4;
  });
  std::map<NodeId, int> rim_edges;
  for (const auto& [e, sides] : edge_sides)
    if (sides == 3) ++rim_edges[e.first], ++rim_edges[e.second];
  ASSERT_FALSE(rim_edges.empty());
  for (const auto& [node, count] : rim_edges) EXPECT_EQ(count, 2) << "rim node " << node;
}

TEST(Improve, RandomFieldsStayConformingWatertightAndPositive) {
  std::size_t split = 0;  // pyramids split for a lateral edge's collapse: exercised here too
  for (std::uint32_t seed = 1; seed <= 60; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    ArrayField f(12, 11, 10);
    for (int k = 0; k < 10; ++k)
      for (int j = 0; j < 11; ++j)
        for (int i = 0; i < 12; ++i) f.at(i, j, k) = u(rng) + 0.3f;
    HybridMesh m = mve::march_volume_elements(f, testing::quiet_options());
    const auto before = cell_quality(m);
    std::vector<std::int64_t> unchanged_from;
    const ImproveStats s = improve_mesh(m, 1.0, ImproveOptions{0.3, 0.02}, &unchanged_from);
    split += s.pyramids_split;
    const MeshCheck c = check_mesh(m);
    ASSERT_TRUE(c.valid()) << "seed " << seed << ": " << c.describe();
    // The cells it calls unchanged have the quality they had: reusing it gives what measuring
    // the improved mesh gives, to the bit.
    const auto measured = cell_quality(m), reused = cell_quality(m, before, unchanged_from);
    ASSERT_EQ(reused.size(), measured.size());
    std::size_t kept = 0;
    for (std::size_t k = 0; k < measured.size(); ++k) {
      kept += unchanged_from[k] >= 0;
      for (Metric metric : kMetrics)
        ASSERT_EQ(reused[k].get(metric), measured[k].get(metric))
            << "seed " << seed << " cell " << k;
    }
    if (s.collapsed > 0) {
      EXPECT_LT(kept, measured.size());
    }
    EXPECT_GT(kept, 0u);
  }
  std::printf("[ info ] pyramids split %zu\n", split);
  EXPECT_GT(split, 0u);
}

TEST(Improve, WithNothingToCollapseEveryCellIsUnchanged) {
  ArrayField f(8, 8, 8);
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) f.at(i, j, k) = static_cast<float>(2.5 - std::abs(i - 3.5));
  HybridMesh m = mve::march_volume_elements(f, testing::quiet_options());
  std::vector<std::int64_t> unchanged_from;
  const ImproveStats s = improve_mesh(m, 1.0, ImproveOptions{0.0, 0.02}, &unchanged_from);
  EXPECT_EQ(s.collapsed, 0u);
  ASSERT_EQ(unchanged_from.size(), m.cell_count());
  for (std::size_t c = 0; c < unchanged_from.size(); ++c)
    EXPECT_EQ(unchanged_from[c], static_cast<std::int64_t>(c));
}

TEST(Quality, IdealCellsScoreIdeal) {
  HybridMesh m;
  const double h = std::sqrt(0.5);
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, h},
             {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  m.pyramids.push_back({0, 1, 2, 3, 4});
  m.hexes.push_back({0, 1, 2, 3, 5, 6, 7, 8});
  HybridMesh t;
  t.nodes = {{0, 0, 0},
             {1, 0, 0},
             {0.5, std::sqrt(3.0) / 2, 0},
             {0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)}};
  t.tets.push_back({0, 1, 2, 3});
  for (const HybridMesh* mesh : {&m, &t})
    for (const auto& q : cell_quality(*mesh)) {
      EXPECT_NEAR(q.edge_ratio, 1.0, 1e-6);
      EXPECT_NEAR(q.equiangle_skew, 0.0, 1e-6);
      EXPECT_NEAR(q.scaled_jacobian, 1.0, 1e-6);
    }
  EXPECT_NEAR(cell_quality(t)[0].min_dihedral, std::acos(1.0 / 3.0) * 180 / M_PI, 1e-4);
  EXPECT_NEAR(cell_quality(m)[1].min_dihedral, 90.0, 1e-4);
}

}  // namespace
}  // namespace naris
