#include "tests/solver/meshes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace naris::testing {
namespace {

class LambdaField : public mve::FieldSource {
 public:
  LambdaField(const std::function<double(const Eigen::Vector3d&)>& f, const Eigen::Vector3d& lo,
              const Eigen::Vector3d& hi, double h)
      : f_(f) {
    for (int a = 0; a < 3; ++a)
      frame_.dims[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / h)) + 1;
    frame_.spacing = Eigen::Vector3d::Constant(h);
    frame_.origin = lo;
  }
  const ImageFrame& frame() const override { return frame_; }
  void read_slice(int k, std::span<float> out) const override {
    for (int j = 0; j < frame_.dims[1]; ++j)
      for (int i = 0; i < frame_.dims[0]; ++i)
        out[static_cast<std::size_t>(i + frame_.dims[0] * j)] =
            static_cast<float>(f_(frame_.physical(Eigen::Vector3d(i, j, k))));
  }

 private:
  std::function<double(const Eigen::Vector3d&)> f_;
  ImageFrame frame_;
};

// Boundary faces of a structured box: the cube faces on its six sides.
void add_box_boundary(HybridMesh& m, int n) {
  auto id = [n](int i, int j, int k) {
    return static_cast<NodeId>(i + (n + 1) * (j + (n + 1) * k));
  };
  m.add_patch("wall");
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      // Outward orientation on each side.
      m.boundary_quads.push_back(
          {id(a, b, 0), id(a, b + 1, 0), id(a + 1, b + 1, 0), id(a + 1, b, 0)});
      m.boundary_quads.push_back(
          {id(a, b, n), id(a + 1, b, n), id(a + 1, b + 1, n), id(a, b + 1, n)});
      m.boundary_quads.push_back(
          {id(a, 0, b), id(a + 1, 0, b), id(a + 1, 0, b + 1), id(a, 0, b + 1)});
      m.boundary_quads.push_back(
          {id(a, n, b), id(a, n, b + 1), id(a + 1, n, b + 1), id(a + 1, n, b)});
      m.boundary_quads.push_back(
          {id(0, a, b), id(0, a, b + 1), id(0, a + 1, b + 1), id(0, a + 1, b)});
      m.boundary_quads.push_back(
          {id(n, a, b), id(n, a + 1, b), id(n, a + 1, b + 1), id(n, a, b + 1)});
    }
  for (std::size_t q = 0; q < m.boundary_quads.size(); ++q) m.boundary_quad_patch.push_back(0);
}

HybridMesh box_nodes(int n) {
  HybridMesh m;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        m.nodes.push_back(Eigen::Vector3d(-1 + 2.0 * i / n, -1 + 2.0 * j / n, -1 + 2.0 * k / n));
  return m;
}

std::array<NodeId, 8> cube(int n, int i, int j, int k) {
  auto id = [n](int a, int b, int c) {
    return static_cast<NodeId>(a + (n + 1) * (b + (n + 1) * c));
  };
  return {id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
          id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
}

}  // namespace

HybridMesh box_hex(int n) {
  HybridMesh m = box_nodes(n);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) m.hexes.push_back(cube(n, i, j, k));
  add_box_boundary(m, n);
  return m;
}

HybridMesh box_tet(int n) {
  HybridMesh m = box_nodes(n);
  // Kuhn's six tetrahedra along the diagonal 0–6, the same in every cube: conforming.
  static const int paths[6][4] = {{0, 1, 2, 6}, {0, 1, 5, 6}, {0, 4, 5, 6},
                                  {0, 4, 7, 6}, {0, 3, 7, 6}, {0, 3, 2, 6}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const auto c = cube(n, i, j, k);
        for (const auto& p : paths) {
          std::array<NodeId, 4> t{c[p[0]], c[p[1]], c[p[2]], c[p[3]]};
          const Eigen::Vector3d a = m.nodes[t[1]] - m.nodes[t[0]],
                                b = m.nodes[t[2]] - m.nodes[t[0]],
                                d = m.nodes[t[3]] - m.nodes[t[0]];
          if (a.cross(b).dot(d) < 0) std::swap(t[1], t[2]);
          m.tets.push_back(t);
        }
      }
  add_box_boundary(m, n);
  return m;
}

HybridMesh mve_mesh(const std::function<double(const Eigen::Vector3d&)>& inside, double lo,
                    double hi, double h) {
  return mve_mesh_box(inside, Eigen::Vector3d::Constant(lo), Eigen::Vector3d::Constant(hi), h,
                      mve::MveOptions{});
}

HybridMesh mve_mesh_box(const std::function<double(const Eigen::Vector3d&)>& inside,
                        const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double h,
                        const mve::MveOptions& options) {
  const LambdaField field(inside, lo, hi, h);
  return mve::march_volume_elements(field, options);
}

HybridMesh convergence_mesh(const std::string& kind, int n) {
  if (kind == "hex") return box_hex(n);
  if (kind == "tet") return box_tet(n);
  const double h = 2.0 / n;
  if (kind == "mve-box")
    return mve_mesh([](const Eigen::Vector3d& x) { return 0.93 - x.cwiseAbs().maxCoeff(); },
                    -1.0 - 0.37 * h, 1.0 + 0.5 * h, h);
  if (kind == "mve-ball")
    return mve_mesh(
        [](const Eigen::Vector3d& x) {
          return 0.95 - (x - Eigen::Vector3d(0.013, -0.021, 0.017)).norm();
        },
        -1.0 - 0.37 * h, 1.0 + 0.5 * h, h);
  throw std::invalid_argument("unknown convergence mesh " + kind);
}

std::vector<NodeId> boundary_nodes(const HybridMesh& mesh) {
  std::vector<NodeId> b;
  for (const auto& t : mesh.boundary_tris) b.insert(b.end(), t.begin(), t.end());
  for (const auto& q : mesh.boundary_quads) b.insert(b.end(), q.begin(), q.end());
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  return b;
}

}  // namespace naris::testing
