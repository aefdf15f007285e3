#include "mesh/hybrid_mesh.h"

#include <algorithm>

namespace naris {

int HybridMesh::patch_id(const std::string& name) const {
  const auto it = std::find(patch_names.begin(), patch_names.end(), name);
  return it == patch_names.end() ? -1 : static_cast<int>(it - patch_names.begin());
}

int HybridMesh::add_patch(const std::string& name) {
  const int id = patch_id(name);
  if (id >= 0) return id;
  patch_names.push_back(name);
  return static_cast<int>(patch_names.size()) - 1;
}

Eigen::Vector3d polygon_vector_area(const HybridMesh& m, std::span<const NodeId> nodes) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < nodes.size(); ++i)
    sum += m.nodes[nodes[i]].cross(m.nodes[nodes[(i + 1) % nodes.size()]]);
  return 0.5 * sum;
}

double polygon_area(const HybridMesh& m, std::span<const NodeId> nodes) {
  return polygon_vector_area(m, nodes).norm();
}

double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

double pyramid_volume(const HybridMesh& m, const std::array<NodeId, 5>& p) {
  const auto& x = m.nodes;
  // Exact for a planar base; for a warped base this is the mean of the two diagonal splits.
  const double v1 = tet_volume(x[p[0]], x[p[1]], x[p[2]], x[p[4]]) +
                    tet_volume(x[p[0]], x[p[2]], x[p[3]], x[p[4]]);
  const double v2 = tet_volume(x[p[0]], x[p[1]], x[p[3]], x[p[4]]) +
                    tet_volume(x[p[1]], x[p[2]], x[p[3]], x[p[4]]);
  return 0.5 * (v1 + v2);
}

double hex_volume(const HybridMesh& m, const std::array<NodeId, 8>& h) {
  // Divergence theorem over the six (possibly warped) faces, each split from its centroid c
  // into four triangles: their c·(a × b) terms sum to c·((x₂ − x₀) × (x₃ − x₁)). Coordinates
  // relative to node 0, which a closed surface allows, keep the products small.
  std::array<Eigen::Vector3d, 8> x;
  for (int n = 0; n < 8; ++n) x[n] = m.nodes[h[n]] - m.nodes[h[0]];
  double v = 0.0;
  for (const auto& f : kHexFaces) {
    const auto& q = f.v;
    const Eigen::Vector3d c = 0.25 * (x[q[0]] + x[q[1]] + x[q[2]] + x[q[3]]);
    v += c.dot((x[q[2]] - x[q[0]]).cross(x[q[3]] - x[q[1]]));
  }
  return v / 6.0;
}

double mesh_volume(const HybridMesh& m) {
  double v = 0.0;
  for (const auto& t : m.tets)
    v += tet_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]);
  for (const auto& p : m.pyramids) v += pyramid_volume(m, p);
  for (const auto& h : m.hexes) v += hex_volume(m, h);
  return v;
}

void flip_orientation(HybridMesh& m) {
  for (auto& t : m.tets) std::swap(t[1], t[2]);
  for (auto& p : m.pyramids) std::swap(p[1], p[3]);
  for (auto& h : m.hexes) {
    std::swap(h[1], h[3]);
    std::swap(h[5], h[7]);
  }
  for (auto& f : m.boundary_tris) std::swap(f[1], f[2]);
  for (auto& f : m.boundary_quads) std::swap(f[1], f[3]);
}

void remove_empty_patches(HybridMesh& m) {
  std::vector<std::size_t> count(m.patch_names.size(), 0);
  for (auto p : m.boundary_tri_patch) ++count[static_cast<std::size_t>(p)];
  for (auto p : m.boundary_quad_patch) ++count[static_cast<std::size_t>(p)];
  std::vector<std::int32_t> renumber(m.patch_names.size(), -1);
  std::vector<std::string> names;
  for (std::size_t p = 0; p < count.size(); ++p) {
    if (!count[p]) continue;
    renumber[p] = static_cast<std::int32_t>(names.size());
    names.push_back(m.patch_names[p]);
  }
  for (auto& p : m.boundary_tri_patch) p = renumber[static_cast<std::size_t>(p)];
  for (auto& p : m.boundary_quad_patch) p = renumber[static_cast<std::size_t>(p)];
  m.patch_names = std::move(names);
}

void compact_nodes(HybridMesh& m) {
  std::vector<NodeId> renumber(m.nodes.size(), -1);
  auto mark = [&](auto& cells) {
    for (const auto& c : cells)
      for (NodeId n : c) renumber[n] = 0;
  };
  mark(m.tets);
  mark(m.pyramids);
  mark(m.hexes);
  NodeId next = 0;
  for (std::size_t i = 0; i < renumber.size(); ++i) {
    if (renumber[i] < 0) continue;
    renumber[i] = next;
    m.nodes[next++] = m.nodes[i];
  }
  m.nodes.resize(static_cast<std::size_t>(next));
  auto apply = [&](auto& cells) {
    for (auto& c : cells)
      for (NodeId& n : c) n = renumber[n];
  };
  apply(m.tets);
  apply(m.pyramids);
  apply(m.hexes);
  apply(m.boundary_tris);
  apply(m.boundary_quads);
}

HybridMesh boundary_surface(const HybridMesh& mesh) {
  HybridMesh s;
  s.patch_names = mesh.patch_names;
  std::vector<NodeId> local(mesh.nodes.size(), -1);
  auto take = [&](const auto& faces, auto& out) {
    for (auto f : faces) {
      for (NodeId& v : f) {
        auto& l = local[static_cast<std::size_t>(v)];
        if (l < 0) {
          l = static_cast<NodeId>(s.nodes.size());
          s.nodes.push_back(mesh.nodes[static_cast<std::size_t>(v)]);
        }
        v = l;
      }
      out.push_back(f);
    }
  };
  take(mesh.boundary_tris, s.boundary_tris);
  take(mesh.boundary_quads, s.boundary_quads);
  s.boundary_tri_patch = mesh.boundary_tri_patch;
  s.boundary_quad_patch = mesh.boundary_quad_patch;
  return s;
}

}  // namespace naris
