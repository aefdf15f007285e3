// The outlet extension: a tube of the outlet's own section added beyond it. Against the meshes
// without it: the outlet's section unchanged and moved by the length, the volume grown by exactly
// section × length, the inlet untouched, along every image axis and on both sides of a cut, in a
// turned and anisotropic frame.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "mesh/patches/outlet_extension.h"
#include "mesh/patches/section_planes.h"
#include "mesh/quality/check.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

using testing::ArrayField;

// A pipe of elliptic section along `axis`, widening along it (a copy of the wrong voxel plane
// would change the section), in a frame turned about (1, 1, 1) with unequal spacings.
ArrayField tapered_pipe(int axis) {
  std::array<int, 3> dims{24, 24, 24};
  dims[static_cast<std::size_t>(axis)] = 40;
  ArrayField f(dims[0], dims[1], dims[2]);
  ImageFrame& frame = f.mutable_frame();
  frame.spacing = Eigen::Vector3d(0.6, 0.7, 0.9);
  frame.origin = Eigen::Vector3d(-3.0, 5.0, 1.5);
  frame.direction = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 1).normalized()).matrix();
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) {
        const int ijk[3] = {i, j, k};
        const double along = ijk[axis], a = ijk[(axis + 1) % 3] - 11.3,
                     b = ijk[(axis + 2) % 3] - 12.6;
        const double s = 1.0 + 0.01 * along;
        f.at(i, j, k) =
            static_cast<float>(1.0 - std::pow(a / (6.2 * s), 2) - std::pow(b / (4.1 * s), 2));
      }
  return f;
}

struct Patch {
  double area = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // area-weighted
};

Patch patch(const HybridMesh& m, const std::string& name) {
  Patch p{.centroid = patch_centroid(m, m.patch_id(name))};
  for (const PatchReport& r : patch_report(m))
    if (r.name == name) p.area = r.area;
  return p;
}

HybridMesh mesh(const mve::FieldSource& field, const std::vector<Cut>& cuts) {
  mve::MveOptions o = testing::quiet_options();
  const PreparedCuts prepared = prepare_cuts(field, cuts, o);
  HybridMesh m = mve::march_volume_elements(field, o);
  finish_patches(m, field, cuts, prepared, {}, o.wall_patch);
  return m;
}

TEST(OutletExtension, AddsATubeOfTheOutletsSectionAlongEveryAxisOnBothSides) {
  const char names[] = "ijk";
  for (int axis = 0; axis < 3; ++axis)
    for (const auto& [inlet, outlet] : {std::pair{3, 30}, std::pair{35, 5}}) {
      SCOPED_TRACE(fmt::format("axis {}, inlet {}, outlet {}", names[axis], inlet, outlet));
      const ArrayField f = tapered_pipe(axis);
      const std::vector<Cut> cuts{
          {"inlet", parse_cut_plane(fmt::format("{}={}", names[axis], inlet))},
          {"outlet", parse_cut_plane(fmt::format("{}={}", names[axis], outlet))}};
      const HybridMesh plain = mesh(f, cuts);

      mve::MveOptions prepared = testing::quiet_options();
      prepare_cuts(f, cuts, prepared);
      const double length = 7.3;  // mm: 12 voxels of 0.6, 10 of 0.7, 8 of 0.9
      const OutletExtension extended(f, cuts, prepared, length);
      const double tube = extended.length_mm();
      EXPECT_NEAR(tube, length, 0.5 * f.frame().spacing[axis]);
      const HybridMesh m = mesh(extended, extended.cuts());
      const MeshCheck check = check_mesh(m);
      ASSERT_TRUE(check.valid()) << check.describe();

      const Patch in0 = patch(plain, "inlet"), in1 = patch(m, "inlet");
      const Patch out0 = patch(plain, "outlet"), out1 = patch(m, "outlet");
      EXPECT_NEAR(in1.area, in0.area, 1e-9 * in0.area);
      EXPECT_NEAR((in1.centroid - in0.centroid).norm(), 0.0, 1e-9);
      EXPECT_NEAR(out1.area, out0.area, 1e-9 * out0.area);
      // Out of the kept part, along the axis.
      const Eigen::Vector3d away =
          f.frame().direction.col(axis) * (outlet > inlet ? 1.0 : -1.0) * tube;
      EXPECT_NEAR((out1.centroid - out0.centroid - away).norm(), 0.0, 1e-9);
      EXPECT_NEAR(mesh_volume(m) - mesh_volume(plain), out0.area * tube, 1e-9 * out0.area * tube);
    }
}

TEST(OutletExtension, RefusesAnObliqueOutletAndALengthBelowAVoxel) {
  const ArrayField f = tapered_pipe(2);
  const auto refused = [&](const std::string& outlet, double length, const std::string& why) {
    const std::vector<Cut> cuts{{"inlet", parse_cut_plane("k=3")},
                                {"outlet", parse_cut_plane(outlet)}};
    mve::MveOptions prepared = testing::quiet_options();
    prepare_cuts(f, cuts, prepared);
    try {
      OutletExtension(f, cuts, prepared, length);
      ADD_FAILURE() << "expected an error: " << why;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  const Eigen::Vector3d p = f.frame().physical(Eigen::Vector3d(11, 12, 30));
  const Eigen::Vector3d n = f.frame().direction * Eigen::Vector3d(0.0, 0.3, 1.0);
  refused(fmt::format("p={},{},{};n={},{},{}", p[0], p[1], p[2], n[0], n[1], n[2]), 5.0,
          "is oblique");
  refused("k=30", 0.3, "shorter than a voxel");
}

}  // namespace
}  // namespace naris
