// Segmentation (4.2.2): histogram threshold, 26-connected region growing, keep-largest, NRRD.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "core/error.h"
#include "mesh/image/read_volume.h"
#include "mesh/image/resample.h"
#include "mesh/image/segment.h"
#include "mesh/image/write_volume.h"

namespace naris {
namespace {

namespace fs = std::filesystem;

// A CT-like volume: tissue (40 HU) with air blobs (−1000 HU), Gaussian noise of 30 HU.
Volume<float> ct(int n, const std::vector<std::pair<Voxel, Voxel>>& air_boxes, unsigned seed = 1) {
  Volume<float> v;
  v.frame.dims = {n, n, n};
  v.frame.spacing = Eigen::Vector3d(0.5, 0.5, 1.0);
  v.frame.origin = Eigen::Vector3d(10, -20, 30);
  v.values.assign(v.frame.voxel_count(), 40.0f);
  for (const auto& [lo, hi] : air_boxes)
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) v.at(i, j, k) = -1000.0f;
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 30.0f);
  for (float& x : v.values) x += noise(rng);
  return v;
}

std::size_t count(const Volume<std::uint8_t>& m) {
  return static_cast<std::size_t>(std::count(m.values.begin(), m.values.end(), 1));
}

TEST(Segment, AutomaticThresholdLandsBetweenAirAndTissue) {
  const auto v = ct(40, {{{2, 2, 2}, {30, 25, 35}}});
  const double t = air_threshold(v);
  EXPECT_GT(t, -850.0);
  EXPECT_LT(t, -150.0);
  Volume<float> flat = v;
  std::fill(flat.values.begin(), flat.values.end(), 5.0f);
  EXPECT_THROW(air_threshold(flat), Error);
}

TEST(Segment, GrowsOnlyTheSeededRegionWith26Connectivity) {
  // Two blobs apart, and a third touching the first only at one corner voxel.
  const auto v =
      ct(30, {{{2, 2, 2}, {8, 8, 8}}, {{20, 20, 20}, {26, 26, 26}}, {{9, 9, 9}, {12, 12, 12}}});
  const auto m = grow_region(v, -500.0, InsideRule::below, {{4, 4, 4}});
  EXPECT_EQ(count(m), 7u * 7 * 7 + 4u * 4 * 4);  // the corner contact joins, the far blob does not
  EXPECT_EQ(m.at(10, 10, 10), 1);
  EXPECT_EQ(m.at(22, 22, 22), 0);
  EXPECT_EQ(m.frame.origin, v.frame.origin);
  const auto both = grow_region(v, -500.0, InsideRule::below, {{4, 4, 4}, {22, 22, 22}});
  EXPECT_EQ(count(both), 7u * 7 * 7 + 4u * 4 * 4 + 7u * 7 * 7);
}

TEST(Segment, SeedsOutsideOrNotInAirAreErrors) {
  const auto v = ct(20, {{{2, 2, 2}, {8, 8, 8}}});
  EXPECT_THROW(parse_seed("25,3,3", v.frame), Error);
  EXPECT_THROW(parse_seed("3,3", v.frame), Error);
  try {
    grow_region(v, -500.0, InsideRule::below, {{15, 15, 15}});
    FAIL() << "a seed in tissue was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not inside"), std::string::npos) << e.what();
  }
  // Physical seeds: x = origin + spacing·index.
  const Voxel s = parse_seed("12, -18, 34 mm", v.frame);
  EXPECT_EQ(s, (Voxel{4, 4, 4}));
}

TEST(Segment, KeepsTheLargestComponent) {
  const auto v = ct(30, {{{2, 2, 2}, {8, 8, 8}}, {{20, 20, 20}, {22, 22, 22}}});
  auto m = threshold_mask(v, -500.0, InsideRule::below);
  const ComponentSummary s = keep_largest_component(m);
  EXPECT_EQ(s.components, 2u);
  EXPECT_EQ(s.kept_voxels, 343u);
  EXPECT_EQ(s.dropped_voxels, 27u);
  EXPECT_EQ(count(m), 343u);
}

TEST(Segment, LabelmapNrrdRoundTrip) {
  const auto v = ct(20, {{{2, 3, 4}, {8, 9, 10}}});
  const auto m = grow_region(v, -500.0, InsideRule::below, {{5, 5, 5}});
  const fs::path p = fs::temp_directory_path() / "naris-mask.nrrd";
  write_labelmap_nrrd(m, p);
  const Volume<float> back = read_volume(p);
  EXPECT_EQ(back.dims(), m.dims());
  EXPECT_NEAR((back.frame.origin - m.frame.origin).norm(), 0.0, 1e-9);
  EXPECT_NEAR((back.frame.spacing - m.frame.spacing).norm(), 0.0, 1e-9);
  for (std::size_t n = 0; n < m.values.size(); ++n) ASSERT_EQ(back.values[n], m.values[n]);
  fs::remove(p);
}

}  // namespace
}  // namespace naris

namespace naris {
namespace {

Volume<float> linear_field(std::array<int, 3> dims, const Eigen::Vector3d& c) {
  Volume<float> v;
  v.frame.dims = dims;
  v.frame.spacing = Eigen::Vector3d(0.3, 0.4, 1.5);
  v.frame.origin = Eigen::Vector3d(-5, 7, 2);
  v.frame.direction =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  v.values.resize(v.frame.voxel_count());
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i)
        v.at(i, j, k) = static_cast<float>(c.dot(v.frame.physical(Eigen::Vector3d(i, j, k))));
  return v;
}

// Averaging a linear field over a block gives its value at the block's centre.
TEST(Resample, DecimationAveragesBlocksAroundTheirCentres) {
  const Eigen::Vector3d c(0.7, -1.1, 0.4);
  const auto v = linear_field({13, 10, 4}, c);
  const auto d = decimate_in_plane(v, 3);
  EXPECT_EQ(d.dims(), (std::array<int, 3>{4, 3, 4}));
  EXPECT_NEAR(d.frame.spacing[0], 0.9, 1e-12);
  EXPECT_NEAR(d.frame.spacing[2], 1.5, 1e-12);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(d.at(i, j, k), c.dot(d.frame.physical(Eigen::Vector3d(i, j, k))), 1e-4);
  EXPECT_THROW(decimate_in_plane(v, 0), Error);
  EXPECT_THROW(decimate_in_plane(v, 7), Error);
}

// Trilinear resampling reproduces linear fields: every voxel of the rotated grid that falls
// inside the original holds the field's value at its physical position.
TEST(Resample, RotationReproducesLinearFieldsAndCoversTheVolume) {
  const Eigen::Vector3d c(0.2, 0.5, -0.3);
  const auto v = linear_field({20, 16, 10}, c);
  const auto r = rotate_about_axis(v, 0, 30.0, -5000.0f);
  std::size_t inside = 0;
  for (int k = 0; k < r.dims()[2]; ++k)
    for (int j = 0; j < r.dims()[1]; ++j)
      for (int i = 0; i < r.dims()[0]; ++i) {
        if (r.at(i, j, k) == -5000.0f) continue;
        ++inside;
        ASSERT_NEAR(r.at(i, j, k), c.dot(r.frame.physical(Eigen::Vector3d(i, j, k))), 1e-3);
      }
  // The rotated grid holds about as many inside voxels as the original has.
  EXPECT_GT(inside, 20u * 16 * 10 * 8 / 10);
  EXPECT_NEAR(std::abs(r.frame.direction.determinant()), 1.0, 1e-12);
  // A quarter turn about k: the new i axis runs along the old j axis (15 × 0.4 = 6 mm) with the
  // i spacing 0.3 mm, the new j axis along the old i axis (19 × 0.3 = 5.7 mm) with 0.4 mm.
  const auto q = rotate_about_axis(v, 2, 90.0, 0.0f);
  EXPECT_EQ(q.dims()[0], static_cast<int>(std::floor(6.0 / 0.3 + 1e-9)) + 1);
  EXPECT_EQ(q.dims()[1], static_cast<int>(std::floor(5.7 / 0.4 + 1e-9)) + 1);
  EXPECT_EQ(q.dims()[2], 10);
}

}  // namespace
}  // namespace naris
