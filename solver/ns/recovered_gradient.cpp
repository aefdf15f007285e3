#include "solver/ns/recovered_gradient.h"

#include "solver/ns/oseen_element.h"

namespace naris::ns {

void recover_gradient(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& a,
                      std::vector<Eigen::Matrix<double, 1, 9>>& gradient,
                      std::vector<double>& mass) {
  gradient.assign(mesh.nodes.size(), Eigen::Matrix<double, 1, 9>::Zero());
  mass.assign(mesh.nodes.size(), 0.0);
  auto run = [&](const auto& cells, auto element) {
    using E = decltype(element);
    constexpr int N = E::nodes;
    const ShapeTable<E>& table = ShapeTable<E>::get();
    Eigen::Matrix<double, N, 3> X, A;
    for (const auto& cell : cells) {
      for (int i = 0; i < N; ++i) {
        X.row(i) = mesh.nodes[static_cast<std::size_t>(cell[i])].transpose();
        A.row(i) = a[static_cast<std::size_t>(cell[i])].transpose();
      }
      for (std::size_t q = 0; q < table.points.size(); ++q) {
        const auto m = fem::map_to_cell<E>(X, table.shapes[q]);
        const double w = table.points[q].weight * m.det_jacobian;
        const Eigen::Matrix3d g = A.transpose() * m.gradient;  // g(c, d) = ∂a_c/∂x_d
        const Eigen::Matrix<double, 1, 9> row =
            Eigen::Map<const Eigen::Matrix<double, 1, 9>>(Eigen::Matrix3d(g.transpose()).data());
        for (int i = 0; i < N; ++i) {
          const auto n = static_cast<std::size_t>(cell[i]);
          gradient[n] += w * m.value[i] * row;
          mass[n] += w * m.value[i];
        }
      }
    }
  };
  run(mesh.tets, fem::Tet4{});
  run(mesh.pyramids, fem::Pyr5{});
  run(mesh.hexes, fem::Hex8{});
  for (std::size_t n = 0; n < mass.size(); ++n)
    if (mass[n] > 0.0) gradient[n] /= mass[n];
}

}  // namespace naris::ns
