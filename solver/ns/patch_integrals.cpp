#include "solver/ns/patch_integrals.h"

namespace naris::ns {

double patch_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u, int patch) {
  double flux = 0.0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> v, int id) {
    if (id != patch) return;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (NodeId n : v) mean += u[static_cast<std::size_t>(n)];
    flux += polygon_vector_area(mesh, v).dot(mean) / static_cast<double>(v.size());
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
