#include "solver/ns/patch_integrals.h"

#include <array>

namespace naris::ns {

double face_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u,
                 std::span<const NodeId> v) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (NodeId n : v) mean += u[static_cast<std::size_t>(n)];
  return polygon_vector_area(mesh, v).dot(mean) / static_cast<double>(v.size());
}

double patch_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u, int patch) {
  double flux = 0.0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> v, int id) {
    if (id == patch) flux += face_flux(mesh, u, v);
  });
  return flux;
}

Eigen::Vector3d patch_momentum_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u,
                                    int patch) {
  Eigen::Vector3d flux = Eigen::Vector3d::Zero();
  for_each_boundary_face(mesh, [&](std::span<const NodeId> v, int id) {
    if (id != patch) return;
    const auto at = [&](std::size_t i) -> const Eigen::Vector3d& {
      return u[static_cast<std::size_t>(v[i])];
    };
    // Fan triangles from the first corner, each by its edge midpoints (degree 2).
    for (std::size_t k = 1; k + 1 < v.size(); ++k) {
      const std::array<NodeId, 3> tri{v[0], v[k], v[k + 1]};
      const Eigen::Vector3d an = polygon_vector_area(mesh, tri);
      const Eigen::Vector3d mid[3] = {(at(0) + at(k)) / 2, (at(k) + at(k + 1)) / 2,
                                      (at(k + 1) + at(0)) / 2};
      for (const auto& m : mid) flux += m * m.dot(an) / 3.0;
    }
  });
  return flux;
}

PatchIntegral patch_integral(const HybridMesh& mesh, const std::vector<double>& values, int patch) {
  double sum = 0.0, area = 0.0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> v, int id) {
    if (id != patch) return;
    const double a = polygon_area(mesh, v);
    double mean = 0.0;
    for (NodeId n : v) mean += values[static_cast<std::size_t>(n)];
    sum += a * mean / static_cast<double>(v.size());
    area += a;
  });
  return {sum, area};
}

}  // namespace naris::ns
