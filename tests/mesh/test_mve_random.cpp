// Random scalar fields, from white noise to smooth blobs, on grids up to 64³.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "core/error.h"
#include "mesh/quality/check.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

using testing::ArrayField;

ArrayField random_field(std::mt19937& rng, std::array<int, 3> dims, int smoothing) {
  ArrayField field(dims[0], dims[1], dims[2]);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> v(field.frame().voxel_count());
  for (float& x : v) x = u(rng);
  // Box smoothing makes larger structures with the same kinds of ambiguity.
  for (int pass = 0; pass < smoothing; ++pass) {
    std::vector<float> w(v.size());
    const auto& f = field.frame();
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i) {
          float s = 0.0f;
          int n = 0;
          for (int dk = -1; dk <= 1; ++dk)
            for (int dj = -1; dj <= 1; ++dj)
              for (int di = -1; di <= 1; ++di) {
                const int a = i + di, b = j + dj, c = k + dk;
                if (a < 0 || b < 0 || c < 0 || a >= dims[0] || b >= dims[1] || c >= dims[2])
                  continue;
                s += v[f.index(a, b, c)];
                ++n;
              }
          w[f.index(i, j, k)] = s / static_cast<float>(n);
        }
    v.swap(w);
  }
  const float shift =
      std::uniform_real_distribution<float>(-0.2f, 0.2f)(rng) / static_cast<float>(1 + smoothing);
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) field.at(i, j, k) = v[field.frame().index(i, j, k)] + shift;
  return field;
}

void check_random(std::uint32_t seed, std::array<int, 3> dims, int smoothing) {
  std::mt19937 rng(seed);
  ArrayField field = random_field(rng, dims, smoothing);
  mve::MveStats stats;
  HybridMesh mesh;
  try {
    mesh = mve::march_volume_elements(field, testing::quiet_options(), &stats);
  } catch (const Error&) {
    return;  // nothing inside: a legitimate outcome for a random field
  }
  const MeshCheck c = check_mesh(mesh);
  ASSERT_TRUE(c.valid()) << "seed " << seed << ": " << c.describe();
  ASSERT_EQ(stats.unresolved_cubes, 0u) << "seed " << seed;
  ASSERT_NEAR(mesh_volume(mesh), testing::boundary_volume(mesh),
              1e-9 * static_cast<double>(field.frame().voxel_count()))
      << "seed " << seed;
}

TEST(MveRandom, SmallNoisyFieldsAreConformingWatertightAndPositive) {
  std::mt19937 sizes(99);
  std::uniform_int_distribution<int> n(2, 14);
  for (std::uint32_t seed = 1; seed <= 400; ++seed)
    check_random(seed, {n(sizes), n(sizes), n(sizes)}, static_cast<int>(seed % 3));
}

TEST(MveRandom, LargeFieldsUpTo64Cubed) {
  check_random(1001, {64, 64, 64}, 0);
  check_random(1002, {64, 64, 64}, 1);
  check_random(1003, {64, 48, 40}, 2);
}

// Components counted from every cell's nodes, independently of the mesher's bookkeeping.
std::size_t count_components(const HybridMesh& m) {
  std::vector<NodeId> parent(m.nodes.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](NodeId a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  auto unite = [&](const auto& cells) {
    for (const auto& c : cells)
      for (NodeId n : c) parent[find(n)] = find(c[0]);
  };
  unite(m.tets);
  unite(m.pyramids);
  unite(m.hexes);
  std::vector<char> used(m.nodes.size(), 0);
  auto mark = [&](const auto& cells) {
    for (const auto& c : cells) used[find(c[0])] = 1;
  };
  mark(m.tets);
  mark(m.pyramids);
  mark(m.hexes);
  return static_cast<std::size_t>(std::count(used.begin(), used.end(), 1));
}

TEST(MveRandom, ComponentCountMatchesAnIndependentCount) {
  int multi = 0, with_hexes = 0;
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    std::mt19937 rng(seed);
    const ArrayField field = random_field(rng, {24, 20, 18}, 2);
    mve::MveOptions all = testing::quiet_options();
    HybridMesh everything;
    try {
      everything = mve::march_volume_elements(field, all);
    } catch (const Error&) {
      continue;
    }
    mve::MveOptions largest = all;
    largest.keep_largest_component = true;
    mve::MveStats stats;
    const HybridMesh kept = mve::march_volume_elements(field, largest, &stats);
    EXPECT_EQ(stats.components, count_components(everything)) << "seed " << seed;
    multi += stats.components > 1;
    with_hexes += everything.hexes.size() > 100;
    EXPECT_EQ(count_components(kept), 1u) << "seed " << seed;
    EXPECT_EQ(kept.cell_count() + stats.dropped_cells, everything.cell_count()) << "seed " << seed;
  }
  // The fields must exercise what is tested: several components, interior hexahedra.
  EXPECT_GT(multi, 10);
  EXPECT_GT(with_hexes, 10);
}

TEST(MveRandom, KeepsTheLargestComponentOnly) {
  ArrayField field(12, 6, 6);
  for (int k = 1; k < 5; ++k)
    for (int j = 1; j < 5; ++j) {
      for (int i = 1; i < 5; ++i) field.at(i, j, k) = 1.0f;  // 4×4×4 block
      field.at(8, j, k) = (j < 3 && k < 3) ? 1.0f : -1.0f;   // small separate speck
    }
  mve::MveOptions o = testing::quiet_options();
  o.keep_largest_component = true;
  mve::MveStats stats;
  const HybridMesh mesh = mve::march_volume_elements(field, o, &stats);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.dropped_components, 1u);
  EXPECT_GT(stats.dropped_cells, 0u);
  EXPECT_TRUE(check_mesh(mesh).valid());
  for (const auto& x : mesh.nodes) EXPECT_LT(x[0], 6.0);
}

}  // namespace
}  // namespace naris
