// A sphere sampled as a signed distance field: the mesh volume converges to 4πr³/3 at second
// order in the voxel size, and boundary nodes lie within the interpolation error of the sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mesh/quality/check.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

struct SphereResult {
  double volume_error;
  double max_surface_distance;
};

SphereResult mesh_sphere(double radius, double h) {
  const int n = static_cast<int>(std::ceil(2.0 * radius / h)) + 5;
  testing::ArrayField field(n, n, n);
  field.mutable_frame().spacing = Eigen::Vector3d::Constant(h);
  // Centre off the grid's symmetry so that no isopoint sits at a special place.
  const Eigen::Vector3d centre =
      Eigen::Vector3d::Constant(0.5 * (n - 1) * h) + Eigen::Vector3d(0.31, -0.17, 0.23) * h;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        field.at(i, j, k) =
            static_cast<float>(radius - (Eigen::Vector3d(i, j, k) * h - centre).norm());
  const HybridMesh mesh = mve::march_volume_elements(field, testing::quiet_options());
  EXPECT_TRUE(check_mesh(mesh).valid());
  const double exact = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  SphereResult r{std::abs(mesh_volume(mesh) - exact) / exact, 0.0};
  for (const auto& t : mesh.boundary_tris)
    for (NodeId v : t)
      r.max_surface_distance =
          std::max(r.max_surface_distance, std::abs((mesh.nodes[v] - centre).norm() - radius));
  return r;
}

TEST(MveSphere, VolumeConvergesAtSecondOrder) {
  const double radius = 1.0;
  const double hs[] = {0.2, 0.1, 0.05};
  std::vector<SphereResult> r;
  for (double h : hs) r.push_back(mesh_sphere(radius, h));
  for (std::size_t i = 0; i + 1 < r.size(); ++i) {
    const double order = std::log(r[i].volume_error / r[i + 1].volume_error) / std::log(2.0);
    std::printf("[ info ] h %.3f → %.3f: volume error %.3e → %.3e, order %.2f\n", hs[i], hs[i + 1],
                r[i].volume_error, r[i + 1].volume_error, order);
    EXPECT_GT(order, 1.7);
  }
}

TEST(MveSphere, BoundaryNodesLieWithinInterpolationErrorOfTheSurface) {
  const double radius = 1.0;
  for (double h : {0.2, 0.1, 0.05}) {
    const SphereResult r = mesh_sphere(radius, h);
    // Linear interpolation of a distance field along an edge of length h errs by O(h²/r);
    // face and loop centres (means of isopoints) by a chord sagitta of the same order.
    EXPECT_LT(r.max_surface_distance, 0.5 * h * h / radius) << "h " << h;
  }
}

}  // namespace
}  // namespace naris
