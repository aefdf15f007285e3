// The nasal airway of real adult head CTs against expert labels (NasalSeg; Zhang et al. 2024,
// CC BY 4.0: labels 3 right cavity, 4 left cavity, 5 nasopharynx), and its refusals.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.h"
#include "mesh/image/nasal_airway.h"
#include "mesh/image/read_volume.h"
#include "tests/mesh/image/expert_labels.h"

namespace naris {
namespace {
namespace fs = std::filesystem;
using testing::label_mask;
using testing::overlap;

class NasalSeg : public ::testing::TestWithParam<const char*> {};

TEST_P(NasalSeg, AirwayMatchesTheExpertLabels) {
  const fs::path dir = fs::path(NARIS_SHARED_DATA) / "nasalseg";
  const fs::path ct_file = dir / (std::string(GetParam()) + "_img.nrrd");
  if (!fs::exists(ct_file)) GTEST_SKIP() << "shared data absent: " << ct_file;
  const Volume<float> ct = read_volume(ct_file);
  const Volume<float> labels = read_volume(dir / (std::string(GetParam()) + "_seg.nrrd"));

  NasalAirwayOptions both;
  both.side = NasalSide::both;
  both.keep_nasopharynx = true;
  const NasalAirway all = segment_nasal_airway(ct, both);
  const testing::Overlap o = overlap(all.mask.values, label_mask(labels, {3, 4, 5}));
  EXPECT_GE(o.dice, 0.80) << "both cavities with the nasopharynx";
  EXPECT_NEAR(o.volume_ratio, 1.0, 0.15);
  ASSERT_EQ(all.nares.size(), 2u);
  EXPECT_GT(all.sinus_ml, 20.0) << "the maxillary sinuses are left out";

  const NasalAirway right = segment_nasal_airway(ct, NasalAirwayOptions{});
  const testing::Overlap r = overlap(right.mask.values, label_mask(labels, {3}));
  EXPECT_GE(r.dice, 0.80) << "right cavity";
  EXPECT_NEAR(r.volume_ratio, 1.0, 0.15);
  ASSERT_EQ(right.nares.size(), 1u);
  EXPECT_TRUE(right.nares[0].right);
  // An adult naris opens downwards, tens to a few hundred mm² of voxel faces.
  EXPECT_LT(right.nares[0].normal[2], -0.5);
  EXPECT_GT(right.nares[0].area, 20.0);
  EXPECT_LT(right.nares[0].area, 400.0);
  ASSERT_TRUE(right.choana.has_value());
  EXPECT_NEAR(*right.choana, testing::last_slice_j(labels, 3.0f), 3);
  EXPECT_EQ(right.outlet, "j=" + std::to_string(*right.choana));
  // Nothing of the airway on the scan's border: the mesher closes it with wall.
  const auto& d = right.mask.frame.dims;
  for (int j = 0; j < d[1]; ++j)
    for (int i = 0; i < d[0]; ++i) EXPECT_EQ(right.mask.at(i, j, d[2] - 1), 0);
}

INSTANTIATE_TEST_SUITE_P(Adults, NasalSeg, ::testing::Values("P005", "P045", "P055"));

// Air with a scanner's noise (a constant would read as a de-identification mask).
float air(int i, int j, int k) {
  return -1000.0f + static_cast<float>((i * 13 + j * 7 + k * 3) % 17);
}

// A head without air inside: tissue in a box of room air wider than the closing's balls.
Volume<float> solid_head() {
  Volume<float> v;
  v.frame.dims = {60, 60, 50};
  v.frame.spacing = {1.0, 1.0, 1.0};
  v.values.resize(v.frame.voxel_count());
  for (int k = 0; k < 50; ++k)
    for (int j = 0; j < 60; ++j)
      for (int i = 0; i < 60; ++i) {
        const bool head = k >= 15 && k < 35 && j >= 15 && j < 45 && i >= 15 && i < 45;
        v.at(i, j, k) = head ? 40.0f + static_cast<float>((i * 7 + j * 3 + k) % 11) : air(i, j, k);
      }
  return v;
}

// A cavity with a nostril through the floor: the test head of the refusals, opened.
Volume<float> head_with_nostril() {
  Volume<float> v = solid_head();
  for (int k = 22; k < 28; ++k)
    for (int j = 22; j < 38; ++j)
      for (int i = 22; i < 38; ++i) v.at(i, j, k) = air(i, j, k);
  for (int k = 15; k < 22; ++k)
    for (int j = 24; j < 30; ++j)
      for (int i = 22; i < 28; ++i) v.at(i, j, k) = air(i, j, k);
  return v;
}

TEST(NasalAirway, RefusesAHeadWithoutAirInside) {
  try {
    segment_nasal_airway(solid_head(), NasalAirwayOptions{.threshold = -400.0});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no air inside the body"), std::string::npos) << e.what();
  }
}

TEST(NasalAirway, RefusesAnInnerCavityWithoutANaris) {
  Volume<float> v = solid_head();
  for (int k = 22; k < 28; ++k)  // a closed cavity: air, but no opening to the room
    for (int j = 22; j < 38; ++j)
      for (int i = 22; i < 38; ++i) v.at(i, j, k) = air(i, j, k);
  try {
    segment_nasal_airway(v, NasalAirwayOptions{.threshold = -400.0});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no naris found"), std::string::npos) << e.what();
  }
}

TEST(NasalAirway, FindsANostrilOpeningDownwardsAndRefusesTheMissingSide) {
  // A cavity and a nostril 6 mm wide through the floor, right of centre.
  const Volume<float> v = head_with_nostril();
  NasalAirwayOptions o{.threshold = -400.0};
  const NasalAirway a = segment_nasal_airway(v, o);
  ASSERT_EQ(a.nares.size(), 1u);
  EXPECT_TRUE(a.nares[0].right);
  EXPECT_LT(a.nares[0].normal[2], -0.9);
  EXPECT_NEAR(a.volume_ml, (16.0 * 16 * 6 + 6.0 * 6 * 7) / 1000.0, 0.3 * (16.0 * 16 * 6) / 1000.0);
  o.side = NasalSide::left;
  EXPECT_THROW(segment_nasal_airway(v, o), Error);
}

TEST(NasalAirway, TakesTheWallsPartialVolumeLayerButBridgesToNoOtherAir) {
  const Volume<float> plain = head_with_nostril();
  const NasalAirway a = segment_nasal_airway(plain, NasalAirwayOptions{});
  ASSERT_LT(a.threshold, a.wall_level);
  const float partial = static_cast<float>(0.5 * (a.threshold + a.wall_level));
  Volume<float> v = plain;
  for (int k = 22; k < 28; ++k) {
    for (int j = 22; j < 38; ++j) v.at(38, j, k) = partial;  // the +i wall's layer: joins
    for (int j = 30; j < 38; ++j) {
      v.at(21, j, k) = partial;  // the -i wall's layer, between the cavity ...
      for (int i = 18; i < 21; ++i) v.at(i, j, k) = air(i, j, k);  // ... and a closed cell
    }
    for (int j = 22; j < 32; ++j) v.at(30, j, k) = partial;  // a fin with air on both sides
  }
  const NasalAirway b = segment_nasal_airway(v, NasalAirwayOptions{});
  EXPECT_DOUBLE_EQ(b.threshold, a.threshold);
  EXPECT_NEAR(b.wall_layer_ml - a.wall_layer_ml, 16 * 6 / 1000.0, 1e-9);
  EXPECT_NEAR(b.volume_ml - a.volume_ml, (16 * 6 - 10 * 6) / 1000.0, 1e-9);
  for (int k = 22; k < 28; ++k) {
    EXPECT_EQ(b.mask.at(38, 30, k), 1);
    EXPECT_EQ(b.mask.at(21, 33, k), 0) << "the layer between the cavity and the cell";
    EXPECT_EQ(b.mask.at(30, 26, k), 0) << "the fin stays";
  }
  // A threshold given by hand is the wall too: no layer.
  const NasalAirway c = segment_nasal_airway(v, NasalAirwayOptions{.threshold = a.threshold});
  EXPECT_EQ(c.wall_layer_ml, 0.0);
  EXPECT_NEAR(c.volume_ml, b.volume_ml - b.wall_layer_ml, 1e-9);
}

}  // namespace
}  // namespace naris
