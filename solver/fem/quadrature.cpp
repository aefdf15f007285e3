#include "solver/fem/quadrature.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.h"

namespace naris::fem {
namespace {

constexpr int kMaxGauss = 8;

// Gauss–Legendre by Newton's method on P_n from the Chebyshev guesses: to round-off for n ≤ 8.
std::vector<std::array<double, 2>> make_gauss_legendre(int n) {
  std::vector<std::array<double, 2>> r(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    r[static_cast<std::size_t>(i)] = {x, 2.0 / ((1.0 - x * x) * dp * dp)};
  }
  return r;
}

int points_for(int degree) {
  return std::max(1, (degree + 2) / 2);
}  // 2n − 1 ≥ degree

std::vector<QuadraturePoint> make_hex(int degree) {
  const auto g = gauss_legendre(points_for(degree));
  std::vector<QuadraturePoint> q;
  for (const auto& c : g)
    for (const auto& b : g)
      for (const auto& a : g) q.push_back({{a[0], b[0], c[0]}, a[1] * b[1] * c[1]});
  return q;
}

std::vector<QuadraturePoint> make_pyramid(int degree) {
  // In collapsed coordinates a polynomial of degree p has degree p in a and b and, with the
  // Jacobian (1−z)², degree p + 2 in c.
  const auto gab = gauss_legendre(points_for(degree));
  const auto gc = gauss_legendre(points_for(degree + 2));
  std::vector<QuadraturePoint> q;
  for (const auto& c : gc) {
    const double z = 0.5 * (1.0 + c[0]), t = 1.0 - z;
    for (const auto& b : gab)
      for (const auto& a : gab)
        q.push_back({{a[0] * t, b[0] * t, z}, a[1] * b[1] * c[1] * t * t / 2.0});
  }
  return q;
}

std::vector<QuadraturePoint> make_tet(int degree) {
  if (degree <= 1) return {{{0.25, 0.25, 0.25}, 1.0 / 6.0}};
  if (degree == 2) {
    // The symmetric 4-point rule (degree 2).
    const double a = 0.5854101966249685, b = 0.1381966011250105, w = 1.0 / 24.0;
    return {{{b, b, b}, w}, {{a, b, b}, w}, {{b, a, b}, w}, {{b, b, a}, w}};
  }
  // Duffy: z = c, y = b(1−c), x = a(1−b)(1−c) on [0,1]³, dV = (1−b)(1−c)² da db dc.
  const auto ga = gauss_legendre(points_for(degree));
  const auto gb = gauss_legendre(points_for(degree + 1));
  const auto gc = gauss_legendre(points_for(degree + 2));
  std::vector<QuadraturePoint> q;
  for (const auto& c : gc)
    for (const auto& b : gb)
      for (const auto& a : ga) {
        const double u = 0.5 * (1 + a[0]), v = 0.5 * (1 + b[0]), w = 0.5 * (1 + c[0]);
        q.push_back({{u * (1 - v) * (1 - w), v * (1 - w), w},
                     a[1] * b[1] * c[1] / 8.0 * (1 - v) * (1 - w) * (1 - w)});
      }
  return q;
}

const std::vector<std::array<double, 2>>& gauss_table(int n) {
  static const auto table = [] {
    std::array<std::vector<std::array<double, 2>>, kMaxGauss + 1> t;
    for (int m = 1; m <= kMaxGauss; ++m) t[m] = make_gauss_legendre(m);
    return t;
  }();
  return table[n];
}

const std::vector<QuadraturePoint>& rule(CellType type, int degree) {
  static const auto table = [] {
    std::array<std::array<std::vector<QuadraturePoint>, kMaxQuadratureDegree + 1>, 3> t;
    for (int d = 0; d <= kMaxQuadratureDegree; ++d) {
      t[static_cast<int>(CellType::tet4)][d] = make_tet(d);
      t[static_cast<int>(CellType::pyr5)][d] = make_pyramid(d);
      t[static_cast<int>(CellType::hex8)][d] = make_hex(d);
    }
    return t;
  }();
  return table[static_cast<int>(type)][degree];
}

}  // namespace

std::span<const std::array<double, 2>> gauss_legendre(int n) {
  if (n < 1 || n > kMaxGauss) fail("Gauss–Legendre rule with {} points is not available", n);
  return gauss_table(n);
}

std::span<const QuadraturePoint> quadrature(CellType type, int degree) {
  if (degree < 0 || degree > kMaxQuadratureDegree)
    fail("no quadrature of degree {} (0 … {})", degree, kMaxQuadratureDegree);
  return rule(type, degree);
}

}  // namespace naris::fem
