#include "solver/ns/reconstruction_derivative.h"

#include <algorithm>
#include <array>
#include <utility>

#include "solver/ns/node_graph.h"
#include "solver/ns/oseen_element.h"

namespace naris::ns {

ReconstructionDerivative::ReconstructionDerivative(const HybridMesh& piece, OwnedCells owned)
    : mesh_(piece),
      owned_(std::move(owned)),
      graph_(node_graph(piece, 0, static_cast<NodeId>(piece.nodes.size()))) {
  const std::size_t edges = graph_.column.size();
  recovery_.resize(3 * edges);
  supg_.resize(3 * edges);
  pspg_.resize(9 * edges);
  gradient_.resize(9 * piece.nodes.size());
  std::vector<double> mass(piece.nodes.size(), 0.0);  // ∫ N_j
  recovery_cells<fem::Tet4>(piece.tets, mass);
  recovery_cells<fem::Pyr5>(piece.pyramids, mass);
  recovery_cells<fem::Hex8>(piece.hexes, mass);
  for (std::size_t j = 0; j < mass.size(); ++j) {
    if (!(mass[j] > 0.0)) continue;
    for (std::size_t e = 3 * graph_.start[j]; e < 3 * graph_.start[j + 1]; ++e)
      recovery_[e] /= mass[j];
  }
}

std::size_t ReconstructionDerivative::edge(NodeId row, NodeId column) const {
  const auto first = graph_.column.begin() + static_cast<std::ptrdiff_t>(graph_.start[row]),
             last = graph_.column.begin() + static_cast<std::ptrdiff_t>(graph_.start[row + 1]);
  return static_cast<std::size_t>(std::lower_bound(first, last, column) - graph_.column.begin());
}

template <class E, class Cells>
void ReconstructionDerivative::recovery_cells(const Cells& cells, std::vector<double>& mass) {
  constexpr int N = E::nodes;
  const ShapeTable<E>& table = ShapeTable<E>::get();
  Eigen::Matrix<double, N, 3> X;
  for (const auto& cell : cells) {
    for (int i = 0; i < N; ++i)
      X.row(i) =
          mesh_.nodes[static_cast<std::size_t>(cell[static_cast<std::size_t>(i)])].transpose();
    for (std::size_t q = 0; q < table.points.size(); ++q) {
      const auto m = fem::map_to_cell<E>(X, table.shapes[q]);
      const double w = table.points[q].weight * m.det_jacobian;
      for (int i = 0; i < N; ++i) {
        const NodeId row = cell[static_cast<std::size_t>(i)];
        mass[static_cast<std::size_t>(row)] += w * m.value[i];
        for (int j = 0; j < N; ++j) {
          const std::size_t e = edge(row, cell[static_cast<std::size_t>(j)]);
          for (int d = 0; d < 3; ++d)
            recovery_[3 * e + static_cast<std::size_t>(d)] += w * m.value[i] * m.gradient(j, d);
        }
      }
    }
  }
}

template <class E, class Cells>
void ReconstructionDerivative::assemble_cells(const Cells& cells,
                                              const std::vector<std::size_t>& owned,
                                              const std::vector<Eigen::Vector3d>& a, double nu) {
  constexpr int N = E::nodes;
  const ShapeTable<E>& table = ShapeTable<E>::get();
  Eigen::Matrix<double, N, 3> X, A;
  std::array<std::size_t, N * N> edges{};  // (i, j) → the edge of row i, column j
  const std::size_t count = owned_.all ? cells.size() : owned.size();
  for (std::size_t k = 0; k < count; ++k) {
    const auto& cell = cells[owned_.all ? k : owned[k]];
    for (int i = 0; i < N; ++i) {
      const auto n = static_cast<std::size_t>(cell[static_cast<std::size_t>(i)]);
      X.row(i) = mesh_.nodes[n].transpose();
      A.row(i) = a[n].transpose();
    }
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        edges[static_cast<std::size_t>(N * i + j)] =
            edge(cell[static_cast<std::size_t>(i)], cell[static_cast<std::size_t>(j)]);
    for (std::size_t q = 0; q < table.points.size(); ++q) {
      const auto m = fem::map_to_cell<E>(X, table.shapes[q]);
      const double w = table.points[q].weight * m.det_jacobian;
      const Eigen::Matrix<double, N, 3>& G = m.gradient;
      const Eigen::Vector3d aq = A.transpose() * m.value;
      const double scale = w * nu * momentum_tau(aq, element_metric<E>(m), nu);
      const Eigen::Matrix<double, N, 1> adv = G * aq;
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) {
          const std::size_t e = edges[static_cast<std::size_t>(N * i + j)];
          for (int d = 0; d < 3; ++d)
            supg_[3 * e + static_cast<std::size_t>(d)] += scale * adv[i] * G(j, d);
          for (int c = 0; c < 3; ++c)
            for (int d = 0; d < 3; ++d)
              pspg_[9 * e + static_cast<std::size_t>(3 * c + d)] += scale * G(i, c) * G(j, d);
        }
    }
  }
}

void ReconstructionDerivative::assemble(const std::vector<Eigen::Vector3d>& a, double nu) {
  std::fill(supg_.begin(), supg_.end(), 0.0f);
  std::fill(pspg_.begin(), pspg_.end(), 0.0f);
  assemble_cells<fem::Tet4>(mesh_.tets, owned_.tets, a, nu);
  assemble_cells<fem::Pyr5>(mesh_.pyramids, owned_.pyramids, a, nu);
  assemble_cells<fem::Hex8>(mesh_.hexes, owned_.hexes, a, nu);
}

void ReconstructionDerivative::apply(const double* v, double* out) {
  // The recovered gradient of v at every piece node: g_j(c, d) = Σ_l R_jl,d v_l,c.
  const std::size_t n = graph_.start.size() - 1;
  for (std::size_t j = 0; j < n; ++j) {
    double g[9] = {};
    for (std::size_t e = graph_.start[j]; e < graph_.start[j + 1]; ++e) {
      const float* r = &recovery_[3 * e];
      const double* vl = v + 4 * static_cast<std::size_t>(graph_.column[e]);
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) g[3 * c + d] += r[d] * vl[c];
    }
    std::copy(g, g + 9, &gradient_[9 * j]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    double sum[4] = {};
    for (std::size_t e = graph_.start[i]; e < graph_.start[i + 1]; ++e) {
      const double* g = &gradient_[9 * static_cast<std::size_t>(graph_.column[e])];
      const float* s = &supg_[3 * e];
      const float* p = &pspg_[9 * e];
      for (int c = 0; c < 3; ++c)
        sum[c] += s[0] * g[3 * c] + s[1] * g[3 * c + 1] + s[2] * g[3 * c + 2];
      for (int k = 0; k < 9; ++k) sum[3] += p[k] * g[k];
    }
    std::copy(sum, sum + 4, out + 4 * i);
  }
}

}  // namespace naris::ns
