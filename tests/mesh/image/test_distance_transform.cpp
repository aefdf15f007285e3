// The exact distance transform against a brute-force search over every target voxel.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mesh/image/distance_transform.h"

namespace naris {
namespace {

ImageFrame frame(int nx, int ny, int nz, double sx, double sy, double sz) {
  ImageFrame f;
  f.dims = {nx, ny, nz};
  f.spacing = {sx, sy, sz};
  return f;
}

double brute_force(const ImageFrame& f, const std::vector<std::uint8_t>& target, int i, int j,
                   int k, bool outside_target) {
  double best = std::numeric_limits<double>::infinity();
  for (int c = 0; c < f.dims[2]; ++c)
    for (int b = 0; b < f.dims[1]; ++b)
      for (int a = 0; a < f.dims[0]; ++a)
        if (target[f.index(a, b, c)])
          best = std::min(best, std::pow((a - i) * f.spacing[0], 2) +
                                    std::pow((b - j) * f.spacing[1], 2) +
                                    std::pow((c - k) * f.spacing[2], 2));
  if (outside_target)
    for (int a = 0; a < 3; ++a) {
      const int x = a == 0 ? i : a == 1 ? j : k;
      best = std::min(best, std::pow((x + 1) * f.spacing[a], 2));
      best = std::min(best, std::pow((f.dims[a] - x) * f.spacing[a], 2));
    }
  return best;
}

TEST(DistanceTransform, EqualsBruteForceOnAnisotropicRandomTargets) {
  const ImageFrame f = frame(13, 9, 7, 0.6, 0.6, 1.5);
  std::mt19937 rng(11);
  std::bernoulli_distribution pick(0.04);
  std::vector<std::uint8_t> target(f.voxel_count());
  for (auto& t : target) t = pick(rng);
  for (OutsideIs outside : {OutsideIs::nothing, OutsideIs::target})
    for (int threads : {1, 2}) {
      const auto d2 = squared_distance(f, target, outside, threads);
      for (int k = 0; k < f.dims[2]; ++k)
        for (int j = 0; j < f.dims[1]; ++j)
          for (int i = 0; i < f.dims[0]; ++i) {
            const double expected = brute_force(f, target, i, j, k, outside == OutsideIs::target);
            EXPECT_NEAR(d2[f.index(i, j, k)], expected, 1e-5 * (1.0 + expected))
                << i << "," << j << "," << k;
          }
    }
}

TEST(DistanceTransform, NoTargetLeavesInfinityAndOutsideBoundsIt) {
  const ImageFrame f = frame(5, 4, 3, 1.0, 2.0, 3.0);
  const std::vector<std::uint8_t> none(f.voxel_count(), 0);
  for (float d : squared_distance(f, none)) EXPECT_TRUE(std::isinf(d));
  const auto d2 = squared_distance(f, none, OutsideIs::target);
  // The centre voxel (2,1,1): nearest outside is across i (3 voxels of 1 mm) or j (2 of 2 mm).
  EXPECT_FLOAT_EQ(d2[f.index(2, 1, 1)], 9.0f);
}

}  // namespace
}  // namespace naris
