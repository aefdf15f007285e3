#include "solver/ns/wall_stress.h"

#include <algorithm>
#include <unordered_map>

#include "core/error.h"
#include "solver/fem/reference_element.h"

namespace naris::ns {
namespace {

using FaceKey = std::array<NodeId, 4>;  // sorted node ids; a triangle's last entry is −1

struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::size_t h = 1469598103934665603ull;
    for (NodeId v : k)
      h = (h ^ static_cast<std::size_t>(static_cast<std::uint32_t>(v))) * 1099511628211ull;
    return h;
  }
};

FaceKey key_of(std::span<const NodeId> v) {
  // The face's ids in increasing order, then −1 (no node id is negative, so −1 sorts first
  // and is moved to the end).
  FaceKey k{-1, -1, -1, -1};
  const std::size_t n = std::min<std::size_t>(v.size(), 4);
  for (std::size_t i = 0; i < n; ++i) {
    NodeId x = v[i];
    std::size_t j = i;
    for (; j > 0 && k[j - 1] > x; --j) k[j] = k[j - 1];
    k[j] = x;
  }
  return k;
}

}  // namespace

WallStress wall_stress(const HybridMesh& mesh, const FlowField& flow, double reynolds) {
  const std::size_t tris = mesh.boundary_tris.size();
  const std::size_t faces = tris + mesh.boundary_quads.size();
  std::unordered_map<FaceKey, std::size_t, FaceKeyHash> index;
  index.reserve(faces);
  for (std::size_t f = 0; f < tris; ++f) index[key_of(mesh.boundary_tris[f])] = f;
  for (std::size_t f = 0; f < mesh.boundary_quads.size(); ++f)
    index[key_of(mesh.boundary_quads[f])] = tris + f;

  WallStress w;
  w.shear.assign(faces, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> traction(faces, Eigen::Vector3d::Zero()), normal_area(faces);
  std::vector<double> pressure(faces, 0.0);
  std::vector<char> found(faces, 0);
  const double nu = 1.0 / reynolds;
  auto visit = [&](const auto& cells, auto element) {
    using E = decltype(element);
    constexpr int N = E::nodes;
    Eigen::Matrix<double, N, 3> X, U;
    for (const auto& cell : cells) {
      bool any = false;
      for (const auto& face : cell_faces(N)) {
        std::array<NodeId, 4> v{};
        for (int i = 0; i < face.size; ++i) v[static_cast<std::size_t>(i)] = cell[face.v[i]];
        const auto it = index.find(key_of(std::span<const NodeId>(v.data(), face.size)));
        if (it == index.end()) continue;
        if (!any) {
          for (int i = 0; i < N; ++i) {
            X.row(i) = mesh.nodes[cell[i]].transpose();
            U.row(i) = flow.velocity[cell[i]].transpose();
          }
          any = true;
        }
        Eigen::Vector3d xi = Eigen::Vector3d::Zero();
        for (int i = 0; i < face.size; ++i) xi += E::node(face.v[i]) / face.size;
        const auto m = fem::map_to_cell<E>(X, E::shape(xi));
        const Eigen::Matrix3d grad = U.transpose() * m.gradient;  // grad(c, d) = ∂u_c/∂x_d
        const Eigen::Vector3d an =
            polygon_vector_area(mesh, std::span<const NodeId>(v.data(), face.size));
        const double area = an.norm();
        const Eigen::Vector3d n = area > 0 ? Eigen::Vector3d(an / area) : Eigen::Vector3d::Zero();
        // The fluid's pull on the boundary: minus the viscous traction σn on the fluid.
        const Eigen::Vector3d viscous = -nu * (grad + grad.transpose()) * n;
        const std::size_t f = it->second;
        traction[f] = viscous;
        w.shear[f] = viscous - viscous.dot(n) * n;
        normal_area[f] = an;
        double p = 0.0;
        for (int i = 0; i < face.size; ++i) p += flow.pressure[cell[face.v[i]]] / face.size;
        pressure[f] = p;
        found[f] = 1;
      }
    }
  };
  visit(mesh.tets, fem::Tet4{});
  visit(mesh.pyramids, fem::Pyr5{});
  visit(mesh.hexes, fem::Hex8{});
  if (std::count(found.begin(), found.end(), 1) != static_cast<std::ptrdiff_t>(faces))
    fail("internal: {} boundary faces belong to no cell",
         faces - static_cast<std::size_t>(std::count(found.begin(), found.end(), 1)));

  w.patches.resize(mesh.patch_names.size());
  for (std::size_t p = 0; p < w.patches.size(); ++p) w.patches[p].name = mesh.patch_names[p];
  for (std::size_t f = 0; f < faces; ++f) {
    const int id = f < tris ? mesh.boundary_tri_patch[f] : mesh.boundary_quad_patch[f - tris];
    PatchForce& pf = w.patches[static_cast<std::size_t>(id)];
    const double area = normal_area[f].norm();
    pf.area += area;
    pf.pressure += pressure[f] * normal_area[f];
    pf.viscous += area * traction[f];
    const double s = w.shear[f].norm();
    pf.mean_shear += area * s;
    pf.max_shear = std::max(pf.max_shear, s);
  }
  for (auto& pf : w.patches)
    if (pf.area > 0) pf.mean_shear /= pf.area;
  return w;
}

}  // namespace naris::ns
