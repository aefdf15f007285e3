#include "solver/ns/patch_integrals.h"

#include <array>
#include <numbers>

namespace naris::ns {

double face_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u,
                 std::span<const NodeId> v) {
  const auto at = [&](std::size_t i) -> const Eigen::Vector3d& {
    return u[static_cast<std::size_t>(v[i])];
  };
  if (v.size() == 3) return polygon_vector_area(mesh, v).dot(at(0) + at(1) + at(2)) / 3.0;
  // A quadrilateral carries the bilinear trace of hexahedra and pyramids: u and the map are
  // bilinear, u·(x_ξ × x_η) has degree 2 in each of ξ, η, and 2×2 Gauss points are exact. (The
  // corner mean times the area is exact only on parallelograms.)
  const auto x = [&](std::size_t i) -> const Eigen::Vector3d& {
    return mesh.nodes[static_cast<std::size_t>(v[i])];
  };
  constexpr double g[2] = {0.5 - 0.5 / std::numbers::sqrt3, 0.5 + 0.5 / std::numbers::sqrt3};
  double flux = 0.0;
  for (double xi : g)
    for (double eta : g) {
      const Eigen::Vector3d dx_dxi = (1 - eta) * (x(1) - x(0)) + eta * (x(2) - x(3));
      const Eigen::Vector3d dx_deta = (1 - xi) * (x(3) - x(0)) + xi * (x(2) - x(1));
      const Eigen::Vector3d ui = (1 - xi) * (1 - eta) * at(0) + xi * (1 - eta) * at(1) +
                                 xi * eta * at(2) + (1 - xi) * eta * at(3);
      flux += 0.25 * ui.dot(dx_dxi.cross(dx_deta));
    }
  return flux;
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
