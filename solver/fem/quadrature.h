#pragma once
// Quadrature rules on the reference cells of reference_element.h, exact for polynomials of a
// requested degree. The hexahedron uses tensor Gauss–Legendre points; the pyramid uses them on
// the collapsed cube x = a(1−z), y = b(1−z), z = (1+c)/2 with dV = (1−z)²/2 da db dc (no point
// at the apex; the rational basis is polynomial in a, b, c there); the tetrahedron uses its
// symmetric 1- and 4-point rules up to degree 2 and a collapsed (Duffy) tensor rule above.
// Every weight is positive. Rules are computed once and shared (read-only, thread-safe).
#include <array>
#include <span>

#include "solver/fem/reference_element.h"

namespace naris::fem {

struct QuadraturePoint {
  Eigen::Vector3d xi;
  double weight;
};

inline constexpr int kMaxQuadratureDegree = 11;

// Throws naris::Error for a degree outside 0 … kMaxQuadratureDegree.
std::span<const QuadraturePoint> quadrature(CellType type, int degree);

// Gauss–Legendre points and weights on [−1, 1] (n ≤ 8).
std::span<const std::array<double, 2>> gauss_legendre(int n);

}  // namespace naris::fem
