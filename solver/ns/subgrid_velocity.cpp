#include "solver/ns/subgrid_velocity.h"

#include "core/error.h"
#include "solver/ns/oseen_element.h"
#include "solver/ns/recovered_gradient.h"

namespace naris::ns {

std::vector<Eigen::Vector3d> subgrid_velocity(const HybridMesh& mesh, const FlowField& field,
                                              double nu, double length_scale) {
  if (field.velocity.size() != mesh.nodes.size() || field.pressure.size() != mesh.nodes.size())
    fail("the field has {} nodes, the mesh {}", field.velocity.size(), mesh.nodes.size());
  if (!(nu > 0.0) || !(length_scale > 0.0)) fail("the viscosity and the length scale must be > 0");
  std::vector<Eigen::Matrix<double, 1, 9>> gradient;
  std::vector<double> mass;
  recover_gradient(mesh, field.velocity, gradient, mass);
  for (auto& g : gradient) g *= length_scale;  // per mesh unit → per unit of the field
  std::vector<Eigen::Vector3d> sub;
  sub.reserve(mesh.cell_count());
  auto run = [&](const auto& cells, auto element) {
    using E = decltype(element);
    constexpr int N = E::nodes;
    const ShapeTable<E>& table = ShapeTable<E>::get();
    Eigen::Matrix<double, N, 3> X, U;
    Eigen::Matrix<double, N, 1> P;
    Eigen::Matrix<double, N, 9> grad;
    for (const auto& cell : cells) {
      for (int i = 0; i < N; ++i) {
        const auto n = static_cast<std::size_t>(cell[i]);
        X.row(i) = mesh.nodes[n].transpose() / length_scale;
        U.row(i) = field.velocity[n].transpose();
        P[i] = field.pressure[n];
        grad.row(i) = gradient[n];
      }
      Eigen::Vector3d integral = Eigen::Vector3d::Zero();
      double volume = 0.0;
      for (std::size_t q = 0; q < table.points.size(); ++q) {
        const auto m = fem::map_to_cell<E>(X, table.shapes[q]);
        const double w = table.points[q].weight * m.det_jacobian;
        const Eigen::Vector3d u = U.transpose() * m.value;
        const Eigen::Vector3d r =
            (U.transpose() * m.gradient) * u + m.gradient.transpose() * P -
            reconstructed_force<N>(Eigen::Vector3d::Zero(), m.gradient, &grad, nu);
        integral -= w * momentum_tau(u, element_metric<E>(m), nu) * r;
        volume += w;
      }
      sub.push_back(integral / volume);
    }
  };
  run(mesh.tets, fem::Tet4{});
  run(mesh.pyramids, fem::Pyr5{});
  run(mesh.hexes, fem::Hex8{});
  return sub;
}

}  // namespace naris::ns
