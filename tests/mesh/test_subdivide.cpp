// Uniform subdivision: the refined mesh is a valid conforming mesh of exactly the same domain —
// same volume, same patches with the same areas and perimeters — with 8 cells per tetrahedron
// and hexahedron and 10 per pyramid, numbered after the parent's nodes.
#include <gtest/gtest.h>

#include <random>

#include "mesh/patches/patches.h"
#include "mesh/quality/check.h"
#include "mesh/refine/subdivide.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

using testing::ArrayField;

HybridMesh cut_ball() {
  const int n = 20;
  ArrayField f(n, n, n);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        f.at(i, j, k) = static_cast<float>(
            8.3 - (Eigen::Vector3d(i, j, k) - Eigen::Vector3d(9.6, 9.2, 9.9)).norm());
  mve::MveOptions o = testing::quiet_options();
  // An axis cut (crop box) and an oblique one (clip plane): both kinds of patch faces.
  const std::vector<Cut> cuts = {{"inlet", parse_cut_plane("k=4")},
                                 {"outlet", parse_cut_plane("p=12,10,10;n=1,0.3,0.2")}};
  const PreparedCuts prepared = prepare_cuts(f, cuts, o);
  HybridMesh m = mve::march_volume_elements(f, o);
  finish_patches(m, f, cuts, prepared, {}, o.wall_patch);
  return m;
}

// The number of distinct edges and quadrilateral faces: the new nodes subdivision must add.
std::size_t distinct_edges_and_quads(const HybridMesh& m) {
  std::vector<std::pair<NodeId, NodeId>> edges;
  std::vector<std::array<NodeId, 4>> quads;
  auto add = [&](const auto& cells) {
    for (const auto& c : cells)
      for (const auto& face : cell_faces(static_cast<int>(c.size()))) {
        for (int i = 0; i < face.size; ++i) {
          NodeId a = c[face.v[i]], b = c[face.v[(i + 1) % face.size]];
          edges.emplace_back(std::min(a, b), std::max(a, b));
        }
        if (face.size == 4) {
          std::array<NodeId, 4> q = {c[face.v[0]], c[face.v[1]], c[face.v[2]], c[face.v[3]]};
          std::sort(q.begin(), q.end());
          quads.push_back(q);
        }
      }
  };
  add(m.tets);
  add(m.pyramids);
  add(m.hexes);
  std::sort(edges.begin(), edges.end());
  std::sort(quads.begin(), quads.end());
  return static_cast<std::size_t>(std::unique(edges.begin(), edges.end()) - edges.begin() +
                                  (std::unique(quads.begin(), quads.end()) - quads.begin()));
}

void expect_same_domain(const HybridMesh& coarse, const HybridMesh& fine) {
  const MeshCheck c = check_mesh(fine);
  ASSERT_TRUE(c.valid()) << c.describe();
  EXPECT_EQ(c.unused_nodes, 0u);
  EXPECT_EQ(fine.tets.size(), 8 * coarse.tets.size() + 4 * coarse.pyramids.size());
  EXPECT_EQ(fine.pyramids.size(), 6 * coarse.pyramids.size());
  EXPECT_EQ(fine.hexes.size(), 8 * coarse.hexes.size());
  EXPECT_EQ(fine.nodes.size(),
            coarse.nodes.size() + distinct_edges_and_quads(coarse) + coarse.hexes.size());
  EXPECT_NEAR(mesh_volume(fine), mesh_volume(coarse), 1e-12 * mesh_volume(coarse));
  const auto before = patch_report(coarse), after = patch_report(fine);
  ASSERT_EQ(before.size(), after.size());
  for (std::size_t p = 0; p < before.size(); ++p) {
    EXPECT_EQ(after[p].name, before[p].name);
    EXPECT_EQ(after[p].faces, 4 * before[p].faces) << before[p].name;
    EXPECT_NEAR(after[p].area, before[p].area, 1e-12 * before[p].area) << before[p].name;
    EXPECT_NEAR(after[p].perimeter, before[p].perimeter, 1e-12 * (1 + before[p].perimeter))
        << before[p].name;
  }
}

TEST(Subdivide, CutBallKeepsItsVolumePatchesAndConformity) {
  const HybridMesh coarse = cut_ball();
  ASSERT_GT(coarse.pyramids.size(), 100u);
  ASSERT_GT(coarse.hexes.size(), 100u);
  ASSERT_GE(coarse.patch_names.size(), 3u);
  const HybridMesh fine = subdivide(coarse);
  expect_same_domain(coarse, fine);
  // Twice: children of children, whose pyramids came from pyramids.
  expect_same_domain(fine, subdivide(fine));
}

TEST(Subdivide, NoisyFieldsWithEveryAmbiguousCaseStayConforming) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int meshed = 0;
  for (int trial = 0; trial < 40; ++trial) {
    ArrayField f(9, 8, 7);
    for (int k = 0; k < 7; ++k)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 9; ++i) f.at(i, j, k) = u(rng);
    HybridMesh coarse;
    try {
      coarse = mve::march_volume_elements(f, testing::quiet_options());
    } catch (const std::exception&) {
      continue;  // nothing inside
    }
    expect_same_domain(coarse, subdivide(coarse));
    ++meshed;
  }
  EXPECT_GT(meshed, 30);
}

// Every refined node is the mean of one input node, an edge's two, a quadrilateral's four or a
// hexahedron's eight; prolonging the input's coordinates gives the refined mesh's.
TEST(Subdivide, ProlongsNodalFieldsAsMeansOfTheParents) {
  const HybridMesh coarse = cut_ball();
  Prolongation p;
  const HybridMesh fine = subdivide(coarse, &p);
  ASSERT_EQ(p.offsets.size(), fine.nodes.size() + 1);
  std::size_t by_count[9] = {};
  for (std::size_t i = 0; i < fine.nodes.size(); ++i) ++by_count[p.offsets[i + 1] - p.offsets[i]];
  EXPECT_EQ(by_count[1], coarse.nodes.size());
  EXPECT_EQ(by_count[2] + by_count[4], distinct_edges_and_quads(coarse));
  EXPECT_EQ(by_count[8], coarse.hexes.size());
  std::vector<double> height(coarse.nodes.size());
  for (std::size_t i = 0; i < height.size(); ++i) height[i] = coarse.nodes[i].z();
  const std::vector<double> prolonged = p.apply(height);
  for (std::size_t i = 0; i < fine.nodes.size(); ++i)
    ASSERT_NEAR(prolonged[i], fine.nodes[i].z(), 1e-12) << "node " << i;
}

// The parent's nodes keep their order and coordinates, and every new node comes after the
// lowest-numbered parent node it lies between: the mesher's slab order survives refinement.
TEST(Subdivide, NumbersNewNodesAfterTheirLowestParent) {
  const HybridMesh coarse = cut_ball();
  const HybridMesh fine = subdivide(coarse);
  std::vector<NodeId> image;  // coarse node → fine node, by coordinates
  NodeId next = 0;
  for (const auto& x : coarse.nodes) {
    while (next < static_cast<NodeId>(fine.nodes.size()) && fine.nodes[next] != x) ++next;
    ASSERT_LT(next, static_cast<NodeId>(fine.nodes.size())) << "a coarse node moved or reordered";
    image.push_back(next++);
  }
  // Each coarse edge's midpoint follows the image of its lower end.
  for (const auto& t : coarse.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const Eigen::Vector3d mid = 0.5 * (coarse.nodes[t[a]] + coarse.nodes[t[b]]);
        const NodeId low = std::min(t[a], t[b]);
        const NodeId end = low + 1 < static_cast<NodeId>(image.size())
                               ? image[low + 1]
                               : static_cast<NodeId>(fine.nodes.size());
        bool found = false;
        for (NodeId n = image[low] + 1; n < end && !found; ++n) found = fine.nodes[n] == mid;
        ASSERT_TRUE(found) << "edge " << t[a] << "-" << t[b];
      }
}

}  // namespace
}  // namespace naris
