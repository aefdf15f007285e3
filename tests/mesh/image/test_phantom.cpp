// The procedural CT phantom (the default case) and the image chain on it: sections against the
// dissertation's Table 4.3, the sampled CT (HU classes, noise, partial volume), subjects that
// differ, and CT → HSR → segmentation against the phantom's exact airway.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "mesh/image/interpolate_slices.h"
#include "mesh/image/phantom.h"
#include "mesh/image/resample.h"
#include "mesh/image/segment.h"

namespace naris {
namespace {

TEST(Phantom, SectionsFollowTable43) {
  // Table 4.3: the naris and six planes, distance from the anterior tip (mm), area (mm²),
  // perimeter (mm).
  const double table[7][3] = {{0.0, 164.0, 46.0},   {33.5, 152.0, 76.0},  {44.0, 197.0, 141.0},
                              {54.5, 213.5, 167.0}, {65.0, 214.5, 161.0}, {75.5, 219.0, 141.0},
                              {85.0, 220.0, 88.0}};
  const NasalPhantom phantom(1);
  for (const auto& row : table) {
    const auto [area, perimeter] = phantom.section_area_perimeter(row[0]);
    std::printf(
        "[ info ] %5.1f mm: area %6.1f mm² (table %6.1f), perimeter %6.1f mm (table %5.1f)\n",
        row[0], area, row[1], perimeter, row[2]);
    EXPECT_NEAR(area, row[1], 0.05 * row[1]) << "at " << row[0] << " mm";
    EXPECT_NEAR(perimeter, row[2], 0.05 * row[2]) << "at " << row[0] << " mm";
  }
  // The nasal valve is the narrowest section, between the vestibule and the main passage.
  const double valve = phantom.section_area_perimeter(14.0)[0];
  EXPECT_LT(valve, 0.5 * phantom.section_area_perimeter(33.5)[0]);
  EXPECT_LT(valve, 0.5 * phantom.section_area_perimeter(0.0)[0]);
}

TEST(Phantom, ExactMaskVolumeIsTheIntegralOfTheSections) {
  const NasalPhantom phantom(1);
  const ImageFrame grid = phantom.frame(0.3, 0.3);
  const Volume<std::uint8_t> mask = phantom_mask(phantom, grid);
  double voxels = 0;
  for (auto v : mask.values) voxels += v;
  // Trapezoidal rule over the section areas, each measured independently on a 0.05 mm grid.
  double integral = 0.0;
  const int n = 96;
  for (int q = 0; q <= n; ++q) {
    const double s = phantom.length() * q / n;
    integral += (q == 0 || q == n ? 0.5 : 1.0) * phantom.section_area_perimeter(s, 0.05)[0];
  }
  integral *= phantom.length() / n;
  // Voxel centres span 0 … length: the end slices count half a voxel outside the airway.
  const double end_sections = 0.5 * 0.3 *
                              (phantom.section_area_perimeter(0.0)[0] +
                               phantom.section_area_perimeter(phantom.length())[0]);
  const double from_mask = voxels * grid.spacing.prod() - end_sections;
  std::printf("[ info ] airway volume: mask %.1f mm³, sections %.1f mm³\n", from_mask, integral);
  EXPECT_NEAR(from_mask, integral, 0.01 * integral);
}

TEST(Phantom, CtHasAirTissueAndBoneWithNoiseAndPartialVolume) {
  const NasalPhantom phantom(1);
  PhantomSampling sampling;
  const Volume<float> ct = render_phantom_ct(phantom, sampling, 2);
  EXPECT_EQ(ct.dims()[2], 33);
  EXPECT_DOUBLE_EQ(ct.frame.spacing[2], 3.0);
  EXPECT_DOUBLE_EQ(ct.frame.spacing[0], 0.3);
  EXPECT_GT(ct.frame.direction.determinant(), 0.0);
  std::size_t air = 0, soft = 0, bone = 0, between = 0;
  for (float v : ct.values) {
    air += v < -900;
    soft += std::abs(v - 40.0f) < 60.0f;
    bone += v > 600;
    between += v > -800 && v < -200;
  }
  const double n = static_cast<double>(ct.values.size());
  std::printf("[ info ] air %.3f, soft tissue %.3f, bone %.3f, partial volume %.3f\n", air / n,
              soft / n, bone / n, between / n);
  EXPECT_GT(air / n, 0.03);
  EXPECT_GT(soft / n, 0.5);
  EXPECT_GT(bone / n, 0.005);
  EXPECT_GT(between / n, 0.005);  // the thick slices blur walls that run obliquely
  // Noise: a corner far from the airway is pure soft tissue.
  double sum = 0, sum2 = 0;
  int count = 0;
  for (int k = 5; k < 30; ++k)
    for (int j = 170; j < 186; ++j)
      for (int i = 85; i < 100; ++i) {
        sum += ct.at(i, j, k);
        sum2 += double(ct.at(i, j, k)) * ct.at(i, j, k);
        ++count;
      }
  const double mean = sum / count, sd = std::sqrt(sum2 / count - mean * mean);
  EXPECT_NEAR(mean, 40.0, 2.0);
  EXPECT_NEAR(sd, sampling.noise, 0.1 * sampling.noise);
  // The automatic threshold lands in the valley between air and soft tissue.
  const double t = air_threshold(ct);
  std::printf("[ info ] automatic threshold %.1f HU\n", t);
  EXPECT_GT(t, -1000.0 + 5 * sampling.noise);
  EXPECT_LT(t, 40.0 - 5 * sampling.noise);
  // The scan does not depend on the thread count.
  PhantomSampling coarse;
  coarse.pixel = 1.0;
  EXPECT_EQ(render_phantom_ct(phantom, coarse, 1).values,
            render_phantom_ct(phantom, coarse, 3).values);
}

// Air runs along a vertical line at lateral offset u, depth s, shorter than `below` mm.
int short_vertical_runs(const NasalPhantom& p, double u, double s, double below) {
  int count = 0;
  double run = 0;
  for (double h = -6; h < 50; h += 0.01) {
    if (p.section_field(u, h, s) < 0) {
      run += 0.01;
    } else {
      count += run > 0 && run < below;
      run = 0;
    }
  }
  return count;
}

TEST(Phantom, SubjectsDiffer) {
  std::vector<double> perimeters;
  for (int subject = 1; subject <= 4; ++subject) {
    const NasalPhantom p(subject);
    double sum = 0;
    for (double s = 35; s <= 75; s += 10) sum += p.section_area_perimeter(s, 0.05)[1];
    perimeters.push_back(sum);
  }
  for (std::size_t a = 0; a < perimeters.size(); ++a)
    for (std::size_t b = a + 1; b < perimeters.size(); ++b)
      EXPECT_GT(std::abs(perimeters[a] - perimeters[b]), 0.005 * perimeters[a])
          << "subjects " << a + 1 << " and " << b + 1;
  // Subject 3's middle meatus is partially obstructed around 60 mm: crossed vertically, 3 mm
  // lateral of the common meatus, it is under 1.2 mm of air where the others have ~2.7 mm.
  EXPECT_GT(short_vertical_runs(NasalPhantom(3), 6.0, 60.0, 1.2), 0);
  EXPECT_EQ(short_vertical_runs(NasalPhantom(1), 6.0, 60.0, 1.2), 0);
  EXPECT_EQ(short_vertical_runs(NasalPhantom(3), 6.0, 40.0, 1.2), 0);
  EXPECT_THROW(NasalPhantom(0), Error);
}

TEST(Phantom, HsrSegmentationMatchesTheExactAirway) {
  // The default case's chain: 3 mm slices → HSR to 0.6 mm → 2×2 in-plane decimation →
  // automatic threshold, region growing from the naris, largest component.
  const NasalPhantom phantom(1);
  const Volume<float> ct = render_phantom_ct(phantom, PhantomSampling{});
  for (const SliceMethod method : {SliceMethod::hsr, SliceMethod::linear}) {
    const Volume<float> fine = decimate_in_plane(interpolate_slices(ct, 2, 4, method), 2);
    const Eigen::Vector3d seed = fine.frame.continuous_index(phantom.seed_point());
    Volume<std::uint8_t> airway = grow_region(
        fine, air_threshold(fine), InsideRule::below,
        {Voxel{static_cast<int>(std::lround(seed[0])), static_cast<int>(std::lround(seed[1])),
               static_cast<int>(std::lround(seed[2]))}});
    keep_largest_component(airway);
    const double d = dice(airway, phantom_mask(phantom, fine.frame));
    std::printf("[ info ] %s: Dice %.4f at %.1f mm\n",
                method == SliceMethod::hsr ? "HSR" : "linear", d, fine.frame.spacing[0]);
    EXPECT_GE(d, 0.9);
  }
}

}  // namespace
}  // namespace naris
