// The mesh check finds each kind of fault it names, whatever the thread count, and its Euler
// characteristics are those of the shapes meshed (a ball 1 and 2, a hollow ball 2 and 4).
#include <gtest/gtest.h>

#include "mesh/quality/check.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

using testing::ArrayField;

// A ball of radius `outer` with, when `inner` > 0, a concentric cavity.
HybridMesh shell(double outer, double inner) {
  const int n = 22;
  ArrayField f(n, n, n);
  const Eigen::Vector3d c(10.37, 10.61, 10.23);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double r = (Eigen::Vector3d(i, j, k) - c).norm();
        f.at(i, j, k) = static_cast<float>(std::min(outer - r, r - inner));
      }
  return mve::march_volume_elements(f, testing::quiet_options());
}

TEST(Check, EulerCharacteristicsOfABallAndAHollowBall) {
  const MeshCheck ball = check_mesh(shell(8.3, -1.0));
  ASSERT_TRUE(ball.valid()) << ball.describe();
  EXPECT_EQ(ball.euler_cells, 1);
  EXPECT_EQ(ball.euler_boundary, 2);
  const MeshCheck hollow = check_mesh(shell(8.3, 3.6));
  ASSERT_TRUE(hollow.valid()) << hollow.describe();
  EXPECT_EQ(hollow.euler_cells, 2);
  EXPECT_EQ(hollow.euler_boundary, 4);
}

TEST(Check, TheSameCountsOnAnyNumberOfThreads) {
  HybridMesh m = shell(8.3, 3.6);
  m.tets.erase(m.tets.begin() + 17,
               m.tets.begin() + 18);  // a fault, so that the counts are not all zero
  const std::string one = check_mesh(m, 1).describe();
  for (int threads : {2, 3, 7}) EXPECT_EQ(check_mesh(m, threads).describe(), one) << threads;
}

TEST(Check, FindsAMissingCell) {
  HybridMesh m = shell(8.3, -1.0);
  ASSERT_GT(m.hexes.size(), 0u);
  m.hexes.erase(m.hexes.begin(),
                m.hexes.begin() + 1);  // an interior hexahedron: its six neighbours lose a partner
  const MeshCheck c = check_mesh(m);
  EXPECT_EQ(c.unmatched_faces, 6u);
  EXPECT_FALSE(c.conforming());
}

TEST(Check, FindsAnInvertedCell) {
  HybridMesh m = shell(8.3, -1.0);
  std::swap(m.hexes[0][1], m.hexes[0][3]);  // mirrored: negative volume, faces turned inward
  std::swap(m.hexes[0][5], m.hexes[0][7]);
  const MeshCheck c = check_mesh(m);
  EXPECT_EQ(c.nonpositive_cells, 1u);
  EXPECT_EQ(c.misoriented_pairs, 6u);
  EXPECT_LT(c.min_volume, 0.0);
}

TEST(Check, FindsADuplicatedCell) {
  HybridMesh m = shell(8.3, -1.0);
  m.tets.push_back(m.tets.front());
  const MeshCheck c = check_mesh(m);
  EXPECT_EQ(c.overshared_faces + c.misoriented_pairs, 4u);
  EXPECT_FALSE(c.conforming());
}

TEST(Check, FindsAHoleAndAnInwardFaceInTheBoundary) {
  HybridMesh holed = shell(8.3, -1.0);
  ASSERT_GT(holed.boundary_tris.size(), 0u);
  holed.boundary_tris.erase(holed.boundary_tris.begin(), holed.boundary_tris.begin() + 1);
  holed.boundary_tri_patch.erase(holed.boundary_tri_patch.begin(),
                                 holed.boundary_tri_patch.begin() + 1);
  const MeshCheck h = check_mesh(holed);
  EXPECT_EQ(h.unmatched_faces, 1u);
  EXPECT_EQ(h.open_boundary_edges, 3u);

  HybridMesh turned = shell(8.3, -1.0);
  std::swap(turned.boundary_tris[0][1], turned.boundary_tris[0][2]);
  const MeshCheck t = check_mesh(turned);
  EXPECT_EQ(t.boundary_mismatches, 1u);
  EXPECT_TRUE(t.watertight());
}

TEST(Check, CountsUnusedNodes) {
  HybridMesh m = shell(8.3, -1.0);
  m.nodes.push_back(Eigen::Vector3d(100.0, 0.0, 0.0));
  const MeshCheck c = check_mesh(m);
  EXPECT_EQ(c.unused_nodes, 1u);
  EXPECT_TRUE(c.conforming());
}

}  // namespace
}  // namespace naris
