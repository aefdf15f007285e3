#include "tests/solver/manufactured.h"

#include <cmath>

#include "solver/fem/quadrature.h"
#include "solver/fem/reference_element.h"
#include "tests/solver/meshes.h"

namespace naris::testing {

// ∫ N_i n dA over the boundary for every node: the flux of a unit nodal velocity.
std::vector<Eigen::Vector3d> boundary_flux_weights(const HybridMesh& mesh) {
  std::vector<Eigen::Vector3d> m(mesh.nodes.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.boundary_tris) {
    const Eigen::Vector3d an =
        (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]) / 6.0;
    for (NodeId v : t) m[static_cast<std::size_t>(v)] += an;
  }
  // Bilinear quadrilaterals: 2×2 Gauss points on (s, t) ∈ [0,1]², n dA = x_s × x_t ds dt.
  const double g[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
  for (const auto& q : mesh.boundary_quads) {
    const Eigen::Vector3d x0 = mesh.nodes[q[0]], x1 = mesh.nodes[q[1]], x2 = mesh.nodes[q[2]],
                          x3 = mesh.nodes[q[3]];
    for (double s : g)
      for (double r : g) {
        const double N[4] = {(1 - s) * (1 - r), s * (1 - r), s * r, (1 - s) * r};
        const Eigen::Vector3d xs = (1 - r) * (x1 - x0) + r * (x2 - x3);
        const Eigen::Vector3d xr = (1 - s) * (x3 - x0) + s * (x2 - x1);
        const Eigen::Vector3d ndA = 0.25 * xs.cross(xr);
        for (int i = 0; i < 4; ++i) m[static_cast<std::size_t>(q[i])] += N[i] * ndA;
      }
  }
  return m;
}

// The exact velocity on every boundary node, corrected along the nodal normals so that the
// discrete net flux is zero: with every velocity fixed, the continuity equations sum to that
// flux, and an interpolation error there would pile up at the node whose pressure is pinned.
ns::DirichletConditions exact_on_boundary(const HybridMesh& mesh, const Exact& u,
                                          const ExactScalar& p) {
  ns::DirichletConditions bc;
  bc.nodes = boundary_nodes(mesh);
  const auto m = boundary_flux_weights(mesh);
  double flux = 0.0, weight = 0.0;
  for (NodeId n : bc.nodes) {
    const auto k = static_cast<std::size_t>(n);
    bc.values.push_back(u(mesh.nodes[k]));
    flux += bc.values.back().dot(m[k]);
    weight += m[k].squaredNorm();
  }
  for (std::size_t i = 0; i < bc.nodes.size(); ++i)
    bc.values[i] -= flux / weight * m[static_cast<std::size_t>(bc.nodes[i])];
  // The pressure level at the node nearest the centre.
  NodeId pin = 0;
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
    if (mesh.nodes[n].norm() < mesh.nodes[static_cast<std::size_t>(pin)].norm())
      pin = static_cast<NodeId>(n);
  bc.pressure_pin = {pin, p(mesh.nodes[static_cast<std::size_t>(pin)])};
  return bc;
}

// L2 errors by a degree-4 rule on every cell; the pressure's mean offset is removed first.
Errors l2_errors(const HybridMesh& mesh, const ns::FlowField& f, const Exact& u,
                 const ExactScalar& p) {
  double volume = 0, offset = 0;
  Errors e;
  for (int pass = 0; pass < 2; ++pass) {
    auto run = [&](const auto& cells, auto element) {
      using E = decltype(element);
      for (const auto& cell : cells) {
        Eigen::Matrix<double, E::nodes, 3> X;
        for (int i = 0; i < E::nodes; ++i) X.row(i) = mesh.nodes[cell[i]].transpose();
        for (const auto& q : fem::quadrature(E::type, 4)) {
          const auto s = E::shape(q.xi);
          const auto m = fem::map_to_cell<E>(X, s);
          const double w = q.weight * m.det_jacobian;
          const Eigen::Vector3d x = X.transpose() * s.value;
          Eigen::Vector3d uh = Eigen::Vector3d::Zero();
          double ph = 0;
          for (int i = 0; i < E::nodes; ++i) {
            uh += s.value[i] * f.velocity[cell[i]];
            ph += s.value[i] * f.pressure[cell[i]];
          }
          if (pass == 0) {
            volume += w;
            offset += w * (ph - p(x));
          } else {
            e.velocity += w * (uh - u(x)).squaredNorm();
            e.pressure += w * std::pow(ph - p(x) - offset, 2);
          }
        }
      }
    };
    run(mesh.tets, fem::Tet4{});
    run(mesh.pyramids, fem::Pyr5{});
    run(mesh.hexes, fem::Hex8{});
    if (pass == 0) offset /= volume;
  }
  e.velocity = std::sqrt(e.velocity);
  e.pressure = std::sqrt(e.pressure);
  return e;
}

constexpr double kA = kBeltramiA, kD = kBeltramiD;
Eigen::Vector3d beltrami(const Eigen::Vector3d& x) {
  const double X = x[0], Y = x[1], Z = x[2];
  return -kA * Eigen::Vector3d(std::exp(kA * X) * std::sin(kA * Y + kD * Z) +
                                   std::exp(kA * Z) * std::cos(kA * X + kD * Y),
                               std::exp(kA * Y) * std::sin(kA * Z + kD * X) +
                                   std::exp(kA * X) * std::cos(kA * Y + kD * Z),
                               std::exp(kA * Z) * std::sin(kA * X + kD * Y) +
                                   std::exp(kA * Y) * std::cos(kA * Z + kD * X));
}
double beltrami_pressure(const Eigen::Vector3d& x) {
  return -0.5 * beltrami(x).squaredNorm();
}

}  // namespace naris::testing
