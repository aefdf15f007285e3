#pragma once
// The element matrix of the stabilized Oseen problem — the Picard linearization of the steady
// incompressible Navier–Stokes equations (eq. 4.6–4.7) about an advection field a — for
// equal-order velocity and pressure on any of the three cell types:
//
//   ν(∇u, ∇w) + ((a·∇)u, w) − (p, ∇·w) + (∇·u, q)                          Galerkin
//   + Σ_K τ_M ((a·∇)u + ∇p − f, (a·∇)w + ∇q)                               SUPG + PSPG
//   + Σ_K τ_C (∇·u, ∇·w)                                                   grad-div (LSIC)
//   = (f, w)
//
// with τ_M = (3 / (a·G a + ν² G:G))^(1/2) and τ_C = 3/(τ_M tr G), G the element metric
// (Shakib, Hughes & Johan 1991; Whiting & Jansen 2001); on a cube of side L these are
// Tezduyar's ((2|a|/h)² + 9(4ν/h²)²)^(−1/2) and h²/(12 τ_M) with h its diameter √3 L. Linear
// elements cannot represent the viscous term νΔu of the residual (it vanishes on tets); dropping it
// makes the stabilization inconsistent and costs the pressure its order. Following Jansen, Collis,
// Whiting & Shakib (1999) it is reconstructed from a recovered nodal gradient of the advection
// field (lagged with the Picard iterate, so it enters as a known force): f_stab = f + ν ∇·(Σ N_j
// G_j). The Laplacian form of the viscous term makes the natural condition ν ∂u/∂n − p n = 0
// ("do-nothing", traction-free for fully developed outflow). With a = u the element residual
// K(u)u − F(u) is the discrete Navier–Stokes residual.
//
// Newton's method needs the derivative of that residual: K(u) plus, for a step δu,
//
//   ((δu·∇)u, w) + Σ_K τ_M ((δu·∇)w, r) + Σ_K τ_M ((u·∇)w + ∇q, (δu·∇)u)
//   + Σ_K δτ_M ((u·∇)w + ∇q, r) + Σ_K δτ_C (∇·u, ∇·w)
//
// with r = (u·∇)u + ∇p − f the strong momentum residual and δτ the change of the τ's with u
// (in the advective regime of the nasal airway they matter as much as the rest). The
// derivative of the reconstructed viscous term reaches beyond the cell (the recovered gradient
// at a node depends on all cells around it): reconstruction_derivative.h applies it beside the
// assembled matrix. Picard keeps only K(u): linear convergence that stalls as Re grows; the
// derivative converges quadratically near the solution.
//
// Degrees of freedom are interleaved per node: (u, v, w, p) of node 0, then node 1, …
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "solver/fem/quadrature.h"
#include "solver/fem/reference_element.h"

namespace naris::ns {

template <int Nodes>
struct ElementSystem {
  Eigen::Matrix<double, 4 * Nodes, 4 * Nodes> K;
  Eigen::Matrix<double, 4 * Nodes, 1> F;
  Eigen::Matrix<double, 4 * Nodes, 1> R;  // K(a)·(a, p) − F: the residual at the iterate
  Eigen::Matrix<double, 4 * Nodes, 4 * Nodes> newton;  // the derivative terms Picard leaves out
};

// What oseen_element computes besides K and F.
enum class Linearization {
  picard,           // K(a), F
  picard_residual,  // and R at (a, p)
  newton,           // and R, and K + the Newton terms
};

// The metric of the reference cell: identity for the pyramid and the hexahedron (side 2); for
// the tetrahedron the matrix [2 1 1; 1 2 1; 1 1 2] that makes the metric independent of which
// vertex is the reference's origin (the unit right tetrahedron seen as an equilateral one, as
// in PHASTA), times 2 — the factor that balances velocity and pressure accuracy on the
// convergence study (docs/results/solver-choices.md).
template <class E>
Eigen::Matrix3d reference_metric() {
  if constexpr (E::type == fem::CellType::tet4) {
    return (Eigen::Matrix3d() << 4, 2, 2, 2, 4, 2, 2, 2, 4).finished();
  } else {
    return Eigen::Matrix3d::Identity();
  }
}

// τ_M at a point with advection a, element metric G and viscosity ν.
inline double momentum_tau(const Eigen::Vector3d& a, const Eigen::Matrix3d& metric, double nu) {
  return std::sqrt(3.0 / (a.dot(metric * a) + nu * nu * metric.squaredNorm()));
}

// The element metric G = J^{-T} J^{-1}, on references of side 2 (the tet's, of side 1, is
// scaled to match): it measures the cell along every direction, so a flat cell gets the small τ
// of its thin direction.
template <class E, class Mapped>
Eigen::Matrix3d element_metric(const Mapped& m) {
  return m.inverse_jacobian.transpose() * reference_metric<E>() * m.inverse_jacobian;
}

// f + ν ∇·(Σ N_j G_j): the force with the viscous term reconstructed from the recovered nodal
// gradient (see the top of this file); `shape_gradient` the cell's ∂N_i/∂x at the point.
template <int N>
Eigen::Vector3d reconstructed_force(const Eigen::Vector3d& f,
                                    const Eigen::Matrix<double, N, 3>& shape_gradient,
                                    const Eigen::Matrix<double, N, 9>* grad, double nu) {
  Eigen::Vector3d f_stab = f;
  if (grad)
    for (int c = 0; c < 3; ++c)
      for (int d = 0; d < 3; ++d) f_stab[c] += nu * shape_gradient.col(d).dot(grad->col(3 * c + d));
  return f_stab;
}

// The quadrature degree for each cell type: 2 is exact for the affine tet's terms; the pyramid
// and the hexahedron use 2×2×2-type rules (3 points across the pyramid's collapsed axis).
inline constexpr int kOseenQuadratureDegree = 2;

// The reference shape values at the quadrature points of one cell type, computed once.
template <class E>
struct ShapeTable {
  std::vector<fem::QuadraturePoint> points;
  std::vector<fem::ShapeValues<E::nodes>> shapes;
  static const ShapeTable& get() {
    static const ShapeTable table = [] {
      ShapeTable t;
      for (const auto& q : fem::quadrature(E::type, kOseenQuadratureDegree)) {
        t.points.push_back(q);
        t.shapes.push_back(E::shape(q.xi));
      }
      return t;
    }();
    return table;
  }
};

// X: node coordinates, a: advection velocity at the nodes (both one row per node); grad: the
// recovered nodal gradient of a, row j = G_j row-major (∂a_c/∂x_d at 3c + d), or null;
// force(x) → f (Eigen::Vector3d) at a physical point; p: the pressure at the nodes (read for
// the residual and the Newton terms only).
template <class E, class Force>
void oseen_element(const Eigen::Matrix<double, E::nodes, 3>& X,
                   const Eigen::Matrix<double, E::nodes, 3>& a,
                   const Eigen::Matrix<double, E::nodes, 9>* grad, double nu, const Force& force,
                   ElementSystem<E::nodes>& out, const Eigen::Matrix<double, E::nodes, 1>& p = {},
                   Linearization linearization = Linearization::picard) {
  constexpr int N = E::nodes;
  const ShapeTable<E>& table = ShapeTable<E>::get();
  const std::size_t nq = table.points.size();
  std::array<fem::MappedValues<N>, 27> mapped;
  for (std::size_t q = 0; q < nq; ++q) mapped[q] = fem::map_to_cell<E>(X, table.shapes[q]);
  const bool newton = linearization == Linearization::newton;
  // The blocks of K summed over the points in compact form and interleaved once at the end:
  // rank-one updates of small dense matrices, not scattered updates of K at every point.
  Eigen::Matrix<double, N, N> momentum = Eigen::Matrix<double, N, N>::Zero();  // per component
  Eigen::Matrix<double, N, N> pressure_pressure = Eigen::Matrix<double, N, N>::Zero();
  Eigen::Matrix<double, 3 * N, 3 * N> grad_div = Eigen::Matrix<double, 3 * N, 3 * N>::Zero();
  std::array<Eigen::Matrix<double, N, N>, 3> velocity_pressure, pressure_velocity;
  velocity_pressure.fill(Eigen::Matrix<double, N, N>::Zero());
  pressure_velocity.fill(Eigen::Matrix<double, N, N>::Zero());
  out.F.setZero();
  if (newton) out.newton.setZero();
  for (std::size_t q = 0; q < nq; ++q) {
    const auto& m = mapped[q];
    const double w = table.points[q].weight * m.det_jacobian;
    const Eigen::Matrix<double, N, 1>& Nv = m.value;
    const Eigen::Matrix<double, N, 3>& G = m.gradient;
    const Eigen::Vector3d aq = a.transpose() * Nv;
    const Eigen::Vector3d f = force(Eigen::Vector3d(X.transpose() * Nv));
    const Eigen::Vector3d f_stab = reconstructed_force<N>(f, G, grad, nu);
    const Eigen::Matrix3d metric = element_metric<E>(m);
    const double tau_m = momentum_tau(aq, metric, nu);
    const double tau_c = 3.0 / (tau_m * metric.trace());
    const Eigen::Matrix<double, N, 1> adv = G * aq;  // (a·∇)N_i
    const Eigen::Matrix<double, N, N> diffusion = G * G.transpose();
    const Eigen::Matrix<double, N, 1> weighted = w * Nv, supg = (w * tau_m) * adv;
    momentum.noalias() += (w * nu) * diffusion + (weighted + supg) * adv.transpose();
    pressure_pressure.noalias() += (w * tau_m) * diffusion;
    // Row and column 3i + c of the grad-div block: G(i, c).
    const Eigen::Matrix<double, N, 3, Eigen::RowMajor> by_node = G;
    const auto g = Eigen::Map<const Eigen::Matrix<double, 3 * N, 1>>(by_node.data());
    grad_div.noalias() += (w * tau_c) * g * g.transpose();
    for (int c = 0; c < 3; ++c) {
      const auto Gc = G.col(c);
      velocity_pressure[static_cast<std::size_t>(c)].noalias() +=
          -Gc * weighted.transpose() + supg * Gc.transpose();
      pressure_velocity[static_cast<std::size_t>(c)].noalias() +=
          weighted * Gc.transpose() + ((w * tau_m) * Gc) * adv.transpose();
      for (int i = 0; i < N; ++i) out.F[4 * i + c] += weighted[i] * f[c] + supg[i] * f_stab[c];
    }
    for (int i = 0; i < N; ++i) out.F[4 * i + 3] += w * tau_m * G.row(i).dot(f_stab);
    if (!newton) continue;
    const Eigen::Matrix3d grad_u = a.transpose() * G;  // (c, d) = ∂u_c/∂x_d
    const Eigen::Vector3d r = grad_u * aq + G.transpose() * p - f_stab;
    const double divergence = grad_u.trace();
    // ∂τ_M/∂a = −τ_M³/3 · G a, and τ_C ∝ 1/τ_M.
    const Eigen::Vector3d dtau = -tau_m * tau_m * tau_m / 3.0 * (metric * aq);
    for (int i = 0; i < N; ++i) {
      const double test = Nv[i] + tau_m * adv[i];
      const Eigen::Vector3d pspg = tau_m * (G.row(i) * grad_u).transpose();
      // What multiplies τ_M in row (i, c) and row (i, p), for the derivative of τ.
      Eigen::Vector4d by_tau;
      for (int c = 0; c < 3; ++c) by_tau[c] = adv[i] * r[c] - tau_c / tau_m * divergence * G(i, c);
      by_tau[3] = G.row(i).dot(r);
      // Row block i's derivative is this 4×3 block times N_j: formed once, not per column.
      Eigen::Matrix<double, 4, 3> row_block;
      for (int d = 0; d < 3; ++d) {
        for (int c = 0; c < 3; ++c)
          row_block(c, d) = test * grad_u(c, d) + tau_m * G(i, d) * r[c] + dtau[d] * by_tau[c];
        row_block(3, d) = pspg[d] + dtau[d] * by_tau[3];
      }
      for (int j = 0; j < N; ++j)
        out.newton.template block<4, 3>(4 * i, 4 * j) += (w * Nv[j]) * row_block;
    }
  }
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 3; ++c)
          out.K(4 * i + c, 4 * j + d) =
              grad_div(3 * i + c, 3 * j + d) + (c == d ? momentum(i, j) : 0.0);
      for (int c = 0; c < 3; ++c) {
        out.K(4 * i + c, 4 * j + 3) = velocity_pressure[static_cast<std::size_t>(c)](i, j);
        out.K(4 * i + 3, 4 * j + c) = pressure_velocity[static_cast<std::size_t>(c)](i, j);
      }
      out.K(4 * i + 3, 4 * j + 3) = pressure_pressure(i, j);
    }
  if (linearization == Linearization::picard) return;
  Eigen::Matrix<double, 4 * N, 1> state;
  for (int i = 0; i < N; ++i) {
    state.template segment<3>(4 * i) = a.row(i).transpose();
    state[4 * i + 3] = p[i];
  }
  out.R.noalias() = out.K * state - out.F;
  if (newton) out.K += out.newton;
}

}  // namespace naris::ns
