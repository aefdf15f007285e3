#include "solver/ns/boundary_conditions.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "core/error.h"

namespace naris::ns {
namespace {

struct InletGeometry {
  std::vector<std::array<NodeId, 4>> faces;  // triangles have v[3] = −1
  std::vector<NodeId> nodes;                 // inlet nodes off the rim (unknowns)
  std::vector<char> rim;                     // per mesh node: on a wall face
  InletSummary summary;
};

// The driven patch's faces, its unknown nodes and its rim (the nodes of every patch but the
// inlet and the outlet).
InletGeometry inlet_geometry(const HybridMesh& mesh, DrivenPatch driven = DrivenPatch::inlet) {
  int inlet = mesh.patch_id("inlet"), outlet = mesh.patch_id("outlet");
  if (inlet < 0) fail("the mesh has no 'inlet' patch (mesh it with --inlet)");
  if (outlet < 0) fail("the mesh has no 'outlet' patch (mesh it with --outlet)");
  const char* name = "inlet";
  if (driven == DrivenPatch::outlet) {
    std::swap(inlet, outlet);
    name = "outlet";
  }
  InletGeometry g;
  g.rim.assign(mesh.nodes.size(), 0);
  std::vector<char> on_inlet(mesh.nodes.size(), 0);
  bool has_outlet = false;
  Eigen::Vector3d area_normal = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  auto visit = [&](std::span<const NodeId> v, int patch) {
    if (patch == outlet) {
      has_outlet = true;
      return;
    }
    if (patch != inlet) {
      for (NodeId n : v) g.rim[static_cast<std::size_t>(n)] = 1;
      return;
    }
    std::array<NodeId, 4> f{v[0], v[1], v[2], v.size() == 4 ? v[3] : -1};
    g.faces.push_back(f);
    for (NodeId n : v) on_inlet[static_cast<std::size_t>(n)] = 1;
    // Fan triangulation from v[0]: exact area vector of a planar polygon.
    for (std::size_t k = 1; k + 1 < v.size(); ++k) {
      const Eigen::Vector3d a = mesh.nodes[v[0]], b = mesh.nodes[v[k]], c = mesh.nodes[v[k + 1]];
      const Eigen::Vector3d an = 0.5 * (b - a).cross(c - a);
      area_normal += an;
      moment += an.norm() * (a + b + c) / 3.0;
    }
  };
  for_each_boundary_face(mesh, visit);
  if (g.faces.empty()) fail("the '{}' patch has no faces", name);
  if (!has_outlet)
    fail("the '{}' patch has no faces", driven == DrivenPatch::outlet ? "inlet" : "outlet");
  g.summary.area = area_normal.norm();
  g.summary.normal = -area_normal / g.summary.area;  // boundary faces point out: flip inward
  g.summary.centroid = moment / g.summary.area;
  for (std::size_t n = 0; n < on_inlet.size(); ++n)
    if (on_inlet[n] && !g.rim[n]) g.nodes.push_back(static_cast<NodeId>(n));
  if (g.nodes.empty())
    fail("the '{}' patch has no node off its rim: it is too small to carry the flow", name);
  return g;
}

// 2D finite elements on the inlet face, projected on its plane: the stiffness −Δ and the load
// ∫ φ_i (which is also the flux weight of node i) over the unknown nodes.
struct FaceSystem {
  Eigen::SparseMatrix<double> stiffness;
  Eigen::VectorXd load;
  std::unordered_map<NodeId, int> index;
};

FaceSystem face_system(const HybridMesh& mesh, const InletGeometry& g) {
  FaceSystem s;
  for (std::size_t k = 0; k < g.nodes.size(); ++k) s.index[g.nodes[k]] = static_cast<int>(k);
  const Eigen::Vector3d n = g.summary.normal;
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  auto plane = [&](NodeId v) {
    const Eigen::Vector3d x = mesh.nodes[v] - g.summary.centroid;
    return Eigen::Vector2d(x.dot(e1), x.dot(e2));
  };
  std::vector<Eigen::Triplet<double>> triplets;
  s.load = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(g.nodes.size()));
  auto add = [&](const NodeId* v, int count, const Eigen::MatrixXd& K, const Eigen::VectorXd& F) {
    for (int i = 0; i < count; ++i) {
      const auto a = s.index.find(v[i]);
      if (a == s.index.end()) continue;  // a rim node: w = 0
      s.load[a->second] += F[i];
      for (int j = 0; j < count; ++j) {
        const auto b = s.index.find(v[j]);
        if (b != s.index.end()) triplets.emplace_back(a->second, b->second, K(i, j));
      }
    }
  };
  const double gauss[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
  for (const auto& f : g.faces) {
    if (f[3] < 0) {
      const Eigen::Vector2d p0 = plane(f[0]), p1 = plane(f[1]), p2 = plane(f[2]);
      Eigen::Matrix2d J;
      J << p1 - p0, p2 - p0;
      const double area = 0.5 * std::abs(J.determinant());
      Eigen::Matrix<double, 3, 2> dphi;
      dphi << -1, -1, 1, 0, 0, 1;
      const Eigen::Matrix<double, 3, 2> grad = dphi * J.inverse();
      add(f.data(), 3, area * grad * grad.transpose(), Eigen::Vector3d::Constant(area / 3.0));
    } else {
      const Eigen::Vector2d p[4] = {plane(f[0]), plane(f[1]), plane(f[2]), plane(f[3])};
      Eigen::Matrix4d K = Eigen::Matrix4d::Zero();
      Eigen::Vector4d F = Eigen::Vector4d::Zero();
      for (double a : gauss)
        for (double b : gauss) {
          const Eigen::Vector4d phi((1 - a) * (1 - b), a * (1 - b), a * b, (1 - a) * b);
          Eigen::Matrix<double, 4, 2> dphi;
          dphi << -(1 - b), -(1 - a), 1 - b, -a, b, a, -b, 1 - a;
          Eigen::Matrix2d J = Eigen::Matrix2d::Zero();
          for (int i = 0; i < 4; ++i) J += p[i] * dphi.row(i);
          const double w = 0.25 * std::abs(J.determinant());
          const Eigen::Matrix<double, 4, 2> grad = dphi * J.inverse();
          K += w * grad * grad.transpose();
          F += w * phi;
        }
      add(f.data(), 4, K, F);
    }
  }
  s.stiffness.resize(static_cast<Eigen::Index>(g.nodes.size()),
                     static_cast<Eigen::Index>(g.nodes.size()));
  s.stiffness.setFromTriplets(triplets.begin(), triplets.end());
  return s;
}

// `sign` +1: along the inward normal (into the domain); −1: out of it.
DirichletConditions assemble(const InletGeometry& g, const Eigen::VectorXd& speed,
                             double sign = 1.0) {
  DirichletConditions bc;
  for (std::size_t n = 0; n < g.rim.size(); ++n)
    if (g.rim[n]) {
      bc.nodes.push_back(static_cast<NodeId>(n));
      bc.values.push_back(Eigen::Vector3d::Zero());
    }
  for (std::size_t k = 0; k < g.nodes.size(); ++k) {
    bc.nodes.push_back(g.nodes[k]);
    bc.values.push_back(sign * speed[static_cast<Eigen::Index>(k)] * g.summary.normal);
  }
  return bc;
}

}  // namespace

DirichletConditions airflow_conditions(const HybridMesh& mesh, InletProfile profile,
                                       double mean_speed, InletSummary* summary,
                                       const ProfileShape& shape, DrivenPatch driven) {
  if (!std::isfinite(mean_speed)) fail("the inlet speed is not finite");
  InletGeometry g = inlet_geometry(mesh, driven);
  const FaceSystem s = face_system(mesh, g);
  Eigen::VectorXd speed = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(g.nodes.size()));
  if (profile == InletProfile::developed) {
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(s.stiffness);
    if (solver.info() != Eigen::Success) fail("the inlet profile's Poisson problem is singular");
    speed = solver.solve(s.load);
  } else if (profile == InletProfile::expression) {
    if (!shape) fail("an expression inlet profile needs its expression");
    for (std::size_t k = 0; k < g.nodes.size(); ++k) {
      const Eigen::Vector3d& x = mesh.nodes[g.nodes[k]];
      const double v = shape(x, (x - g.summary.centroid).norm());
      if (!std::isfinite(v) || v < 0.0)
        fail(
            "the inlet profile is {} at ({:.4g}, {:.4g}, {:.4g}): it must be finite and not "
            "negative (air enters through the inlet)",
            v, x[0], x[1], x[2]);
      speed[static_cast<Eigen::Index>(k)] = v;
    }
    if (!(s.load.dot(speed) > 0.0))
      fail("the inlet profile is zero on the whole inlet (off its rim): no air enters");
  }
  // Scale so that the flux is mean_speed × area: the rim is held at zero, so an unscaled
  // "uniform" profile would carry less than its nominal flow.
  speed *= mean_speed * g.summary.area / s.load.dot(speed);
  g.summary.flux = s.load.dot(speed);
  if (summary) *summary = g.summary;
  return assemble(g, speed, driven == DrivenPatch::outlet ? -1.0 : 1.0);
}

DirichletConditions airflow_conditions(const HybridMesh& mesh,
                                       const std::function<double(const Eigen::Vector3d&)>& speed,
                                       InletSummary* summary) {
  InletGeometry g = inlet_geometry(mesh);
  const FaceSystem s = face_system(mesh, g);
  Eigen::VectorXd values(static_cast<Eigen::Index>(g.nodes.size()));
  for (std::size_t k = 0; k < g.nodes.size(); ++k) {
    values[static_cast<Eigen::Index>(k)] = speed(mesh.nodes[g.nodes[k]]);
    if (!std::isfinite(values[static_cast<Eigen::Index>(k)]))
      fail("the inlet profile is not finite at node {}", g.nodes[k]);
  }
  g.summary.flux = s.load.dot(values);
  if (summary) *summary = g.summary;
  return assemble(g, values);
}

}  // namespace naris::ns
