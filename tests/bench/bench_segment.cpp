// Benchmark of segmentation on a 512×512×300 CT-like volume: tissue at 40 HU with a tortuous
// air tree (a thick helix joined to a slab and a ball), noise of 30 HU. Times the automatic
// threshold, 26-connected region growing from one seed, and keep-largest-component.
#include <cmath>
#include <cstdio>
#include <random>

#include "core/log.h"
#include "mesh/image/segment.h"

using namespace naris;

int main() {
  const int nx = 512, ny = 512, nz = 300;
  Volume<float> v;
  v.frame.dims = {nx, ny, nz};
  v.values.resize(v.frame.voxel_count());
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 30.0f);
  for (int k = 0; k < nz; ++k) {
    const double a = k * 0.05, cx = 256 + 150 * std::cos(a), cy = 256 + 150 * std::sin(a);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const bool helix = std::hypot(i - cx, j - cy) < 40;
        const bool slab = k > 240 && k < 270 && i > 60 && i < 450;
        const bool ball = std::hypot(std::hypot(i - 256.0, j - 256.0), k - 60.0) < 70;
        const bool speck = (i % 97 == 5) && (j % 89 == 7) && (k % 31 == 3);
        v.at(i, j, k) = (helix || slab || ball || speck ? -1000.0f : 40.0f) + noise(rng);
      }
  }
  Stopwatch clock;
  const double threshold = air_threshold(v);
  const double t_threshold = clock.seconds();
  clock = Stopwatch();
  const int k0 = 0;
  const Voxel seed{static_cast<int>(256 + 150 * std::cos(0.0)), 256, k0};
  auto mask = grow_region(v, threshold, InsideRule::below, {seed});
  const double t_grow = clock.seconds();
  std::size_t grown = 0;
  for (auto x : mask.values) grown += x;
  clock = Stopwatch();
  auto all = threshold_mask(v, threshold, InsideRule::below);
  const auto summary = keep_largest_component(all);
  const double t_largest = clock.seconds();
  std::printf("%-26s %12s %10s %14s %14s %12s\n", "volume", "threshold", "grow s", "grown voxels",
              "keep-largest s", "components");
  std::printf("%-26s %12.1f %10.3f %14zu %14.3f %12zu\n", "512x512x300 (78.6 M voxels)", threshold,
              t_grow, grown, t_largest, summary.components);
  std::printf(
      "\nthreshold: %.3f s (histogram); peak memory %.0f MB (float image 315 MB + one byte "
      "per voxel per mask)\n",
      t_threshold, static_cast<double>(peak_memory_bytes()) / 1e6);
  return 0;
}
