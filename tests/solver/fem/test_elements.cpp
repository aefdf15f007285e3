// Reference elements and quadrature (solver/fem) against the facts of VERIFICATION.md §1:
// partition of unity, nodal interpolation, linear reproduction, conformity of the pyramid with
// P1 tets and Q1 hexes on its faces, exactness of every quadrature rule on monomials, and the
// reference pyramid's stiffness and mass entries.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.h"
#include "solver/fem/quadrature.h"
#include "solver/fem/reference_element.h"

namespace naris::fem {
namespace {

// A random point inside each reference cell.
Eigen::Vector3d random_point(CellType type, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (type == CellType::hex8) return {2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1};
  if (type == CellType::pyr5) {
    const double z = 0.98 * u(rng);
    return {(2 * u(rng) - 1) * (1 - z), (2 * u(rng) - 1) * (1 - z), z};
  }
  double a = u(rng), b = u(rng), c = u(rng);
  if (a + b + c > 1) {  // fold the cube into the tetrahedron
    a = 1 - a, b = 1 - b;
    if (a + b + c > 1) c = 1 - c;
  }
  return a + b + c <= 1 ? Eigen::Vector3d(a, b, c) : Eigen::Vector3d(0.2, 0.2, 0.2);
}

template <class E>
void check_basis(CellType type) {
  std::mt19937 rng(7);
  for (int n = 0; n < 200; ++n) {
    const Eigen::Vector3d xi = random_point(type, rng);
    const auto s = E::shape(xi);
    EXPECT_NEAR(s.value.sum(), 1.0, 1e-14);
    EXPECT_LT(s.gradient.colwise().sum().norm(), 1e-13);
    // Linear reproduction: Σ N_i ξ_i = ξ and Σ ξ_i ∇N_i = I.
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    Eigen::Matrix3d g = Eigen::Matrix3d::Zero();
    for (int i = 0; i < E::nodes; ++i) {
      x += s.value[i] * E::node(i);
      g += E::node(i) * s.gradient.row(i);
    }
    EXPECT_LT((x - xi).norm(), 1e-14);
    EXPECT_LT((g - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    // Gradients against central differences.
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[k] = 1e-6;
      const Eigen::VectorXd fd = (E::shape(xi + d).value - E::shape(xi - d).value) / 2e-6;
      EXPECT_LT((fd - s.gradient.col(k)).norm(), 1e-8);
    }
  }
  // Nodal interpolation: N_i(node j) = δ_ij.
  for (int j = 0; j < E::nodes; ++j) {
    const auto s = E::shape(E::node(j));
    for (int i = 0; i < E::nodes; ++i) EXPECT_NEAR(s.value[i], i == j ? 1.0 : 0.0, 1e-14);
  }
}

TEST(ReferenceElement, TetIsAPartitionOfUnityThatReproducesLinearFields) {
  check_basis<Tet4>(CellType::tet4);
}
TEST(ReferenceElement, HexIsAPartitionOfUnityThatReproducesLinearFields) {
  check_basis<Hex8>(CellType::hex8);
}
TEST(ReferenceElement, PyramidIsAPartitionOfUnityThatReproducesLinearFields) {
  check_basis<Pyr5>(CellType::pyr5);
  // Approaching the apex the values tend to (0,0,0,0,1), from any direction.
  for (const Eigen::Vector3d& xi :
       {Eigen::Vector3d(1e-9, 0, 1 - 1e-9), Eigen::Vector3d(-1e-9, 1e-9, 1 - 1e-9),
        Eigen::Vector3d(0, 0, 1)}) {
    const auto s = Pyr5::shape(xi);
    EXPECT_NEAR(s.value[4], 1.0, 1e-8);
    EXPECT_NEAR(s.value.head<4>().norm(), 0.0, 1e-8);
  }
}

TEST(ReferenceElement, PyramidMatchesP1OnItsTrianglesAndQ1OnItsBase) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Triangle 0-1-4 lies in y = z − 1; there N_2 = N_3 = 0 and N_0, N_1, N_4 are the
  // barycentric coordinates of the triangle (linear), like a P1 tet's on that face.
  for (int n = 0; n < 100; ++n) {
    double l1 = u(rng), l4 = u(rng);
    if (l1 + l4 > 1) l1 = 1 - l1, l4 = 1 - l4;
    const double l0 = 1 - l1 - l4;
    const Eigen::Vector3d p = l0 * Pyr5::node(0) + l1 * Pyr5::node(1) + l4 * Pyr5::node(4);
    const auto s = Pyr5::shape(p);
    EXPECT_NEAR(s.value[0], l0, 1e-13);
    EXPECT_NEAR(s.value[1], l1, 1e-13);
    EXPECT_NEAR(s.value[4], l4, 1e-13);
    EXPECT_NEAR(s.value[2], 0.0, 1e-13);
    EXPECT_NEAR(s.value[3], 0.0, 1e-13);
  }
  // The base z = 0 is the hexahedron's bottom face z = −1: the same bilinear functions.
  for (int n = 0; n < 100; ++n) {
    const double x = 2 * u(rng) - 1, y = 2 * u(rng) - 1;
    const auto p = Pyr5::shape({x, y, 0});
    const auto h = Hex8::shape({x, y, -1});
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(p.value[i], h.value[i], 1e-14);
    EXPECT_NEAR(p.value[4], 0.0, 1e-15);
  }
}

// ∫ x^a y^b z^c over each reference cell, exactly.
double power_integral_1d(int k) {
  return k % 2 ? 0.0 : 2.0 / (k + 1);
}  // over [−1, 1]
double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}
double exact_monomial(CellType type, int a, int b, int c) {
  switch (type) {
    case CellType::hex8:
      return power_integral_1d(a) * power_integral_1d(b) * power_integral_1d(c);
    case CellType::tet4:
      return factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
    case CellType::pyr5:
      // ∫₀¹ z^c (1−z)^{a+b+2} dz · ∫ x^a · ∫ y^b over [−1, 1]: a Beta function.
      return power_integral_1d(a) * power_integral_1d(b) * factorial(c) * factorial(a + b + 2) /
             factorial(a + b + c + 3);
  }
  return 0.0;
}

TEST(Quadrature, EveryRuleIntegratesMonomialsOfItsDegreeExactly) {
  for (const CellType type : {CellType::tet4, CellType::pyr5, CellType::hex8})
    for (int degree = 0; degree <= kMaxQuadratureDegree; ++degree) {
      const auto rule = quadrature(type, degree);
      for (const auto& q : rule) EXPECT_GT(q.weight, 0.0);
      for (int a = 0; a <= degree; ++a)
        for (int b = 0; a + b <= degree; ++b)
          for (int c = 0; a + b + c <= degree; ++c) {
            double sum = 0.0;
            for (const auto& q : rule)
              sum += q.weight * std::pow(q.xi[0], a) * std::pow(q.xi[1], b) * std::pow(q.xi[2], c);
            EXPECT_NEAR(sum, exact_monomial(type, a, b, c), 1e-13)
                << "cell " << static_cast<int>(type) << " degree " << degree << " monomial " << a
                << b << c;
          }
    }
  EXPECT_EQ(quadrature(CellType::tet4, 2).size(), 4u);
  EXPECT_EQ(quadrature(CellType::hex8, 3).size(), 8u);
  EXPECT_THROW(quadrature(CellType::hex8, kMaxQuadratureDegree + 1), Error);
}

TEST(Quadrature, ReferencePyramidStiffnessAndMassMatchVerification) {
  Eigen::Matrix<double, 5, 5> K = Eigen::Matrix<double, 5, 5>::Zero(), M = K;
  for (const auto& q : quadrature(CellType::pyr5, 2)) {
    const auto s = Pyr5::shape(q.xi);
    K += q.weight * s.gradient * s.gradient.transpose();
    M += q.weight * s.value * s.value.transpose();
  }
  EXPECT_NEAR(K(0, 0), 17.0 / 54.0, 1e-14);
  EXPECT_NEAR(K(0, 1), 1.0 / 54.0, 1e-14);
  EXPECT_NEAR(K(0, 2), -1.0 / 54.0, 1e-14);
  EXPECT_NEAR(K(0, 4), -1.0 / 3.0, 1e-14);
  EXPECT_NEAR(K(4, 4), 4.0 / 3.0, 1e-14);
  EXPECT_NEAR(M(0, 0), 4.0 / 45.0, 1e-14);
  EXPECT_NEAR(M(0, 4), 1.0 / 20.0, 1e-14);
  EXPECT_NEAR(M(4, 4), 2.0 / 15.0, 1e-14);
  EXPECT_NEAR(M.sum(), 4.0 / 3.0, 1e-14);  // the volume
  // Rows of the stiffness sum to zero (constants are in its kernel).
  EXPECT_LT(K.rowwise().sum().norm(), 1e-14);
}

TEST(ReferenceElement, MappedCellsHaveTheirVolumeAndPhysicalGradients) {
  // An affine map x = A ξ + b of each reference cell: ∫ det J = |det A| · reference volume and
  // Σ X_i ⊗ ∇N_i = I (linear fields are reproduced in physical coordinates too).
  Eigen::Matrix3d A;
  A << 2.0, 0.3, -0.1, 0.2, 1.5, 0.4, -0.3, 0.1, 0.8;
  const Eigen::Vector3d b(1.0, -2.0, 0.5);
  auto check = [&](auto element, double reference_volume) {
    using E = decltype(element);
    Eigen::Matrix<double, E::nodes, 3> X;
    for (int i = 0; i < E::nodes; ++i) X.row(i) = (A * E::node(i) + b).transpose();
    double volume = 0.0;
    for (const auto& q : quadrature(E::type, 2)) {
      const auto m = map_to_cell<E>(X, E::shape(q.xi));
      volume += q.weight * m.det_jacobian;
      EXPECT_LT((X.transpose() * m.gradient - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    }
    EXPECT_NEAR(volume, A.determinant() * reference_volume, 1e-13);
  };
  check(Tet4{}, 1.0 / 6.0);
  check(Pyr5{}, 4.0 / 3.0);
  check(Hex8{}, 8.0);
}

}  // namespace
}  // namespace naris::fem
