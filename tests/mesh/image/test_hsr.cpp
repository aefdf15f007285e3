// HSR slice interpolation (ch. 2) on the two-squares test of Fig. 2.11: 17×17 binary images
// with 8×8 squares far apart, 4×4 blocks, 3 pyramid levels.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "mesh/image/hsr.h"

namespace naris {
namespace {

Image2D square(int x0, int y0) {
  Image2D im{17, 17, std::vector<double>(17 * 17, 0.0)};
  for (int y = y0; y < y0 + 8; ++y)
    for (int x = x0; x < x0 + 8; ++x) im.at(x, y) = 1.0;
  return im;
}

// Intersection over union of the image (thresholded at 1/2) with the 8×8 square at (x0, y0).
double iou(const Image2D& a, int x0, int y0) {
  int inter = 0, uni = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const bool p = a.at(x, y) > 0.5, q = x >= x0 && x < x0 + 8 && y >= y0 && y < y0 + 8;
      inter += p && q;
      uni += p || q;
    }
  return static_cast<double>(inter) / uni;
}

TEST(Hsr, TwoSquaresRegisterExactlyAndInterpolateAsSquares) {
  // The square moves by (6, 4) pixels: more than a block, found through the pyramid.
  const Image2D i2 = square(1, 2), i1 = square(7, 6);
  HsrOptions o;
  o.block = 4;
  o.levels = 3;
  o.iterations = 50;
  const Displacement d = register_hsr(i1, i2, o);
  EXPECT_LT(d.msd, 1e-7);
  EXPECT_NEAR(d.u.at(4, 5), 6.0, 0.05);
  EXPECT_NEAR(d.v.at(4, 5), 4.0, 0.05);
  for (double s : {1.0 / 3.0, 0.5, 2.0 / 3.0}) {
    const int x0 = static_cast<int>(std::lround(1 + 6 * s)),
              y0 = static_cast<int>(std::lround(2 + 4 * s));
    const double hsr = iou(interpolate_hsr(i1, i2, d, s), x0, y0);
    const double linear = iou(interpolate_linear(i1, i2, s), x0, y0);
    const Image2D shape_image = interpolate_shape(i1, i2, s);
    const double shape = iou(shape_image, x0, y0);
    int shape_area = 0;
    for (double v : shape_image.v) shape_area += v > 0.5;
    std::printf(
        "[ info ] s = %.2f: IoU with the moved square: HSR %.3f, linear %.3f, shape %.3f "
        "(shape area %d px of 64)\n",
        s, hsr, linear, shape, shape_area);
    EXPECT_GT(hsr, 0.95);
    // The baselines fail here, as in Fig. 2.11: the cross-fade leaves two half-grey squares
    // (nothing or both of them past one half), the blend of distance maps shrinks the square
    // towards the small overlap of the two.
    EXPECT_LT(linear, 0.6);
    EXPECT_LT(shape, 0.8);
    EXPECT_LT(shape_area, 0.75 * 64);
  }
  // The ends are the slices themselves.
  EXPECT_GT(iou(interpolate_hsr(i1, i2, d, 0.0), 1, 2), 0.99);
  EXPECT_GT(iou(interpolate_hsr(i1, i2, d, 1.0), 7, 6), 0.99);
}

TEST(Hsr, SlicesOfDifferentSizeAreAnError) {
  const Image2D a{17, 17, std::vector<double>(289, 0.0)}, b{16, 17, std::vector<double>(272, 0.0)};
  EXPECT_THROW(register_hsr(a, b), Error);
}

}  // namespace
}  // namespace naris

#include "mesh/image/interpolate_slices.h"

namespace naris {
namespace {

// Whole volumes: slices inserted along an axis keep the acquired ones and the frame.
TEST(InterpolateSlices, InsertsSlicesAlongTheAxisAndKeepsTheAcquiredOnes) {
  Volume<float> v;
  v.frame.dims = {3, 17, 17};
  v.frame.spacing = Eigen::Vector3d(3.0, 0.5, 0.5);
  v.values.assign(v.frame.voxel_count(), 0.0f);
  for (int i = 0; i < 3; ++i)
    for (int k = 2 + 2 * i; k < 10 + 2 * i; ++k)
      for (int j = 1 + 3 * i; j < 9 + 3 * i; ++j)
        v.at(i, j, k) = 1.0f;  // a square moving in (j, k)
  for (const char* m : {"hsr", "linear", "shape"}) {
    const Volume<float> out = interpolate_slices(v, 0, 2, parse_slice_method(m), {4, 3, 50}, 2);
    ASSERT_EQ(out.dims(), (std::array<int, 3>{7, 17, 17})) << m;
    EXPECT_DOUBLE_EQ(out.frame.spacing[0], 1.0);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 17; ++j)
        for (int k = 0; k < 17; ++k) ASSERT_EQ(out.at(3 * i, j, k), v.at(i, j, k)) << m;
  }
  // HSR moves the square: the middle slice between acquired slices 0 and 1 is the square at
  // its halfway position (shifted by 1.5 in j and 1 in k), up to a pixel of rounding.
  const Volume<float> h = interpolate_slices(v, 0, 1, SliceMethod::hsr, {4, 3, 50}, 1);
  int count = 0;
  for (int j = 0; j < 17; ++j)
    for (int k = 0; k < 17; ++k) count += h.at(1, j, k) == 1.0f;
  EXPECT_NEAR(count, 64, 10);
  EXPECT_THROW(parse_slice_method("cubic"), Error);
}

}  // namespace
}  // namespace naris

#include <filesystem>

#include "mesh/image/read_volume.h"

namespace naris {
namespace {

// Leave-slices-out on the real airway: keep every third slice along the thick axis and rebuild
// the others; HSR must reproduce the removed slices better than linear interpolation.
TEST(InterpolateSlices, HsrBeatsLinearOnTheNeonateLeavingSlicesOut) {
  const auto path = std::filesystem::path(NARIS_SHARED_DATA) / "neonate-a.nrrd";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  const Volume<float> full = read_volume(path);
  const int n = full.dims()[0];
  Volume<float> kept;
  kept.frame = full.frame;
  kept.frame.dims[0] = (n - 1) / 3 + 1;
  kept.values.resize(kept.frame.voxel_count());
  for (int s = 0; s < kept.frame.dims[0]; ++s)
    set_slice_across(kept, 0, s, slice_across(full, 0, 3 * s));
  auto dice = [&](SliceMethod m) {
    const Volume<float> r = interpolate_slices(kept, 0, 2, m, {8, 4, 30});
    std::size_t inter = 0, sum = 0;
    for (int s = 0; s < std::min(n, r.dims()[0]); ++s) {
      if (s % 3 == 0) continue;
      const Image2D a = slice_across(r, 0, s), b = slice_across(full, 0, s);
      for (std::size_t k = 0; k < a.v.size(); ++k) {
        inter += a.v[k] > 0.5 && b.v[k] > 0.5;
        sum += (a.v[k] > 0.5) + (b.v[k] > 0.5);
      }
    }
    return 2.0 * static_cast<double>(inter) / static_cast<double>(sum);
  };
  const double hsr = dice(SliceMethod::hsr), linear = dice(SliceMethod::linear);
  std::printf("[ info ] leave-slices-out Dice: HSR %.4f, linear %.4f\n", hsr, linear);
  EXPECT_GT(hsr, linear);
}

}  // namespace
}  // namespace naris

namespace naris {
namespace {

// Two labels side by side in a cylinder whose radius changes from slice to slice: the label map
// interpolated label by label keeps each label's volume to within a voxel layer, invents no
// label, and keeps the acquired slices.
TEST(LabelMap, InterpolatesLabelByLabel) {
  Volume<float> v;
  v.frame.dims = {40, 40, 5};
  v.frame.spacing = {0.5, 0.5, 1.5};
  v.values.assign(v.frame.voxel_count(), 0.0f);
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i)
        if (std::hypot(i - 19.5, j - 19.5) < 10.0 + 2.0 * k) v.at(i, j, k) = i < 20 ? 3.0f : 5.0f;
  const std::vector<float> labels = map_labels(v);
  ASSERT_EQ(labels, (std::vector<float>{3.0f, 5.0f}));
  Volume<float> binary = v;
  for (float& x : binary.values) x = x > 0.0f ? 1.0f : 0.0f;
  EXPECT_TRUE(map_labels(binary).empty());
  const Volume<float> out = interpolate_label_map(v, labels, 2, 2, 2);
  ASSERT_EQ(out.frame.dims[2], 13);
  EXPECT_DOUBLE_EQ(out.frame.spacing[2], 0.5);
  double count3 = 0.0, count5 = 0.0;
  for (float x : out.values) {
    EXPECT_TRUE(x == 0.0f || x == 3.0f || x == 5.0f) << x;
    count3 += x == 3.0f, count5 += x == 5.0f;
  }
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i) EXPECT_EQ(out.at(i, j, 3 * k), v.at(i, j, k));
  // Each label is half of a disc whose radius grows linearly, 10 + 2z pixels at slice z.
  double voxels = 0.0;
  for (int q = 0; q < 13; ++q) voxels += 0.5 * M_PI * std::pow(10.0 + 2.0 * q / 3.0, 2);
  EXPECT_NEAR(count3, voxels, 0.05 * voxels);
  EXPECT_NEAR(count5, voxels, 0.05 * voxels);
}

}  // namespace
}  // namespace naris
