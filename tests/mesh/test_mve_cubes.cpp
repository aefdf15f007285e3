// The real mesher on one cube and on two face-sharing cubes, for every inside pattern: the
// meshes must be conforming, watertight and positive, and the cells must fill exactly the
// region their boundary encloses.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "mesh/mve/case_table.h"
#include "mesh/quality/check.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

using testing::ArrayField;

// Vertex values with the given inside pattern (one bit per vertex; vertices past the 32nd are
// outside) and random magnitudes (which move the isopoints and decide the ambiguous faces).
void fill_pattern(ArrayField& field, unsigned pattern, std::mt19937& rng) {
  std::uniform_real_distribution<float> mag(0.05f, 1.0f);
  const auto& d = field.frame().dims;
  int bit = 0;
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i) {
        const bool inside = bit < 32 && (pattern >> bit & 1u);
        ++bit;
        field.at(i, j, k) = inside ? mag(rng) : -mag(rng);
      }
}

void expect_valid(const HybridMesh& mesh, const std::string& what) {
  const MeshCheck c = check_mesh(mesh);
  ASSERT_TRUE(c.valid()) << what << ": " << c.describe();
  ASSERT_NEAR(mesh_volume(mesh), testing::boundary_volume(mesh), 1e-9) << what;
}

TEST(MveCube, EveryConfigurationMeshesOneCubeValidly) {
  std::mt19937 rng(1);
  std::set<std::pair<int, int>> outcomes;
  for (unsigned config = 1; config < 256; ++config) {
    for (int variant = 0; variant < 40; ++variant) {
      ArrayField field(2, 2, 2);
      fill_pattern(field, config, rng);
      mve::MveStats stats;
      const HybridMesh mesh = mve::march_volume_elements(field, testing::quiet_options(), &stats);
      expect_valid(mesh, "config " + std::to_string(config));
      EXPECT_EQ(stats.unresolved_cubes, 0u);
      // The unit cube closes on its own: cells of a full cube make one hexahedron.
      if (config == 255) {
        EXPECT_EQ(mesh.hexes.size(), 1u);
      } else {
        EXPECT_TRUE(mesh.hexes.empty());
      }
    }
  }
}

TEST(MveCube, EveryPairOfFaceSharingCubesIsConforming) {
  std::mt19937 rng(2);
  for (int axis = 0; axis < 3; ++axis) {
    std::array<int, 3> dims{2, 2, 2};
    dims[axis] = 3;
    for (unsigned pattern = 1; pattern < 4096; ++pattern) {
      for (int variant = 0; variant < 2; ++variant) {
        ArrayField field(dims[0], dims[1], dims[2]);
        fill_pattern(field, pattern, rng);
        mve::MveStats stats;
        const HybridMesh mesh = mve::march_volume_elements(field, testing::quiet_options(), &stats);
        expect_valid(mesh, "axis " + std::to_string(axis) + " pattern " + std::to_string(pattern));
        ASSERT_EQ(stats.unresolved_cubes, 0u);
      }
    }
  }
}

TEST(MveCube, MirroredFramesKeepVolumesPositive) {
  std::mt19937 rng(3);
  ArrayField field(4, 4, 4);
  fill_pattern(field, 0x5a5a5a5au, rng);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) field.at(i, j, k) = (i + j + k) % 3 == 0 ? -0.5f : 0.7f;
  field.mutable_frame().direction = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  field.mutable_frame().spacing = Eigen::Vector3d(0.5, 0.25, 2.0);
  const HybridMesh mesh = mve::march_volume_elements(field, testing::quiet_options());
  expect_valid(mesh, "mirrored");
}

}  // namespace
}  // namespace naris
