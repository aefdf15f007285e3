// The flux through one boundary face against the exact integral: on a quadrilateral the cells'
// trace is bilinear in the reference square, which holds every field linear in space, so
// ∫ u·n dA of a linear u is the area times u at the face's centroid, on any quadrilateral.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "solver/ns/patch_integrals.h"

namespace naris::ns {
namespace {

TEST(PatchIntegrals, QuadrilateralFluxIsExactForALinearField) {
  // A trapezoid in z = 0, counter-clockwise seen from +z (its normal), neither a parallelogram
  // nor symmetric, then the same lifted onto a tilted plane.
  const std::array<Eigen::Vector2d, 4> corners = {
      Eigen::Vector2d(0.0, 0.0), {3.0, 0.0}, {2.0, 1.0}, {0.5, 1.0}};
  double area = 0.0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int k = 0; k < 4; ++k) {  // the shoelace formula and its first moments
    const Eigen::Vector2d &p = corners[k], &q = corners[(k + 1) % 4];
    const double cross = p.x() * q.y() - q.x() * p.y();
    area += cross / 2.0;
    centroid += (p + q) * cross / 6.0;
  }
  centroid /= area;
  for (const double tilt : {0.0, 0.4}) {
    HybridMesh mesh;
    for (const auto& c : corners) mesh.nodes.push_back(Eigen::Vector3d(c.x(), c.y(), tilt * c.x()));
    // u = (0.3, −0.2, 1 + 2x − 3y): its flux through the plane z = tilt·x (normal (−tilt, 0, 1)
    // per unit projected area).
    auto u = [](const Eigen::Vector3d& x) {
      return Eigen::Vector3d(0.3, -0.2, 1.0 + 2.0 * x.x() - 3.0 * x.y());
    };
    std::vector<Eigen::Vector3d> velocity;
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n) velocity.push_back(u(mesh.nodes[n]));
    const Eigen::Vector3d at_centroid = u({centroid.x(), centroid.y(), tilt * centroid.x()});
    const double exact = area * (at_centroid.z() - tilt * at_centroid.x());
    const std::array<NodeId, 4> face{0, 1, 2, 3};
    EXPECT_NEAR(face_flux(mesh, velocity, face), exact, 1e-12 * std::abs(exact)) << tilt;
    // The corner mean times the area, exact only on parallelograms, is far off here.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& v : velocity) mean += v / 4.0;
    EXPECT_GT(std::abs(area * (mean.z() - tilt * mean.x()) - exact), 1e-2 * std::abs(exact));
  }
}

}  // namespace
}  // namespace naris::ns
