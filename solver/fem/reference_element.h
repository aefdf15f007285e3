#pragma once
// Reference elements of the hybrid mesh: the linear tetrahedron (P1), the trilinear hexahedron
// (Q1) and the rational pyramid of Bedrosian (1992), whose basis is linear on its triangular
// faces and bilinear on its quadrilateral base, so all three conform across shared faces.
// Node orders are VTK's (VTK_TETRA, VTK_PYRAMID, VTK_HEXAHEDRON), like HybridMesh's cells.
//
//   tet4: (0,0,0) (1,0,0) (0,1,0) (0,0,1)
//   pyr5: base (−1,−1,0) (1,−1,0) (1,1,0) (−1,1,0), apex (0,0,1)
//   hex8: [−1,1]³, bottom (z = −1) counter-clockwise from (−1,−1), then the top
#include <Eigen/Dense>

namespace naris::fem {

enum class CellType { tet4, pyr5, hex8 };

template <int Nodes>
struct ShapeValues {
  Eigen::Matrix<double, Nodes, 1> value;
  Eigen::Matrix<double, Nodes, 3> gradient;  // ∂N_i/∂ξ_j on the reference cell
};

struct Tet4 {
  static constexpr CellType type = CellType::tet4;
  static constexpr int nodes = 4;
  static ShapeValues<4> shape(const Eigen::Vector3d& xi);
  static Eigen::Vector3d node(int i);
};

struct Pyr5 {
  static constexpr CellType type = CellType::pyr5;
  static constexpr int nodes = 5;
  // N_i = ((1−z) + ξ_i x)((1−z) + η_i y) / (4(1−z)) for the base, N_5 = z. Rational: at the
  // apex itself (1 − z ≤ 1e-12) the values' limit (0,0,0,0,1) is returned and the gradient of
  // the base functions is taken as its limit along the axis. Quadrature never samples the apex.
  static ShapeValues<5> shape(const Eigen::Vector3d& xi);
  static Eigen::Vector3d node(int i);
};

struct Hex8 {
  static constexpr CellType type = CellType::hex8;
  static constexpr int nodes = 8;
  static ShapeValues<8> shape(const Eigen::Vector3d& xi);
  static Eigen::Vector3d node(int i);
};

// The mapping of one cell at one reference point: x(ξ) = Σ X_i N_i(ξ).
template <int Nodes>
struct MappedValues {
  Eigen::Matrix<double, Nodes, 1> value;
  Eigen::Matrix<double, Nodes, 3> gradient;  // ∂N_i/∂x_j, physical
  double det_jacobian = 0.0;
  Eigen::Matrix3d inverse_jacobian;  // ∂ξ_k/∂x_j
};

// Values and physical gradients at reference point ξ of a cell with node coordinates X (one
// row per node). The Jacobian J_jk = ∂x_j/∂ξ_k; its determinant is positive for a valid cell.
template <class Element>
MappedValues<Element::nodes> map_to_cell(const Eigen::Matrix<double, Element::nodes, 3>& X,
                                         const ShapeValues<Element::nodes>& s) {
  MappedValues<Element::nodes> m;
  m.value = s.value;
  const Eigen::Matrix3d J = X.transpose() * s.gradient;  // J(j, k) = Σ_i X_ij ∂N_i/∂ξ_k
  m.det_jacobian = J.determinant();
  m.inverse_jacobian = J.inverse();
  // ∇_x N = J^{-T} ∇_ξ N, as rows: gradient = ∇_ξ N · J^{-1}.
  m.gradient = s.gradient * m.inverse_jacobian;
  return m;
}

}  // namespace naris::fem
