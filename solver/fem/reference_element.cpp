#include "solver/fem/reference_element.h"

namespace naris::fem {

ShapeValues<4> Tet4::shape(const Eigen::Vector3d& xi) {
  ShapeValues<4> s;
  s.value << 1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2];
  s.gradient << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return s;
}

Eigen::Vector3d Tet4::node(int i) {
  static const double n[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  return {n[i][0], n[i][1], n[i][2]};
}

namespace {
constexpr double kPyrBase[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
constexpr double kHexNodes[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                    {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
}  // namespace

ShapeValues<5> Pyr5::shape(const Eigen::Vector3d& xi) {
  const double x = xi[0], y = xi[1], z = xi[2];
  const double t = 1.0 - z;
  ShapeValues<5> s;
  if (t <= 1e-12) {
    // The apex: the limit of the values; the base gradients' limit along the axis (a = b = 0).
    s.value << 0, 0, 0, 0, 1;
    for (int i = 0; i < 4; ++i)
      s.gradient.row(i) << kPyrBase[i][0] / 4.0, kPyrBase[i][1] / 4.0, -0.25;
    s.gradient.row(4) << 0, 0, 1;
    return s;
  }
  for (int i = 0; i < 4; ++i) {
    const double xs = kPyrBase[i][0], ys = kPyrBase[i][1];
    const double A = t + xs * x, B = t + ys * y;
    s.value[i] = A * B / (4.0 * t);
    s.gradient(i, 0) = xs * B / (4.0 * t);
    s.gradient(i, 1) = ys * A / (4.0 * t);
    s.gradient(i, 2) = (A * B - (A + B) * t) / (4.0 * t * t);
  }
  s.value[4] = z;
  s.gradient.row(4) << 0, 0, 1;
  return s;
}

Eigen::Vector3d Pyr5::node(int i) {
  if (i == 4) return {0, 0, 1};
  return {kPyrBase[i][0], kPyrBase[i][1], 0};
}

ShapeValues<8> Hex8::shape(const Eigen::Vector3d& xi) {
  ShapeValues<8> s;
  for (int i = 0; i < 8; ++i) {
    const double a = 1 + kHexNodes[i][0] * xi[0], b = 1 + kHexNodes[i][1] * xi[1],
                 c = 1 + kHexNodes[i][2] * xi[2];
    s.value[i] = a * b * c / 8.0;
    s.gradient(i, 0) = kHexNodes[i][0] * b * c / 8.0;
    s.gradient(i, 1) = kHexNodes[i][1] * a * c / 8.0;
    s.gradient(i, 2) = kHexNodes[i][2] * a * b / 8.0;
  }
  return s;
}

Eigen::Vector3d Hex8::node(int i) {
  return {kHexNodes[i][0], kHexNodes[i][1], kHexNodes[i][2]};
}

}  // namespace naris::fem
