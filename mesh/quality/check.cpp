#include "mesh/quality/check.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace naris {
namespace {

struct FaceUse {
  std::array<NodeId, 4> key;    // sorted node ids, padded with the max value for triangles
  std::array<NodeId, 4> cycle;  // the cycle rotated to start at its smallest node
  std::int8_t size;
  std::int8_t source;  // 0: cell, 1: boundary list
};

FaceUse make_face(const NodeId* n, int size, std::int8_t source) {
  FaceUse f;
  f.size = static_cast<std::int8_t>(size);
  f.source = source;
  f.key.fill(std::numeric_limits<NodeId>::max());
  f.cycle.fill(std::numeric_limits<NodeId>::max());
  int start = 0;
  for (int i = 0; i < size; ++i) {
    f.key[i] = n[i];
    if (n[i] < n[start]) start = i;
  }
  std::sort(f.key.begin(), f.key.begin() + size);
  for (int i = 0; i < size; ++i) f.cycle[i] = n[(start + i) % size];
  return f;
}

bool reversed(const FaceUse& a, const FaceUse& b) {
  if (a.size != b.size) return false;
  // b reversed, starting at the same smallest node: b0, b[n-1], ..., b1.
  for (int i = 0; i < a.size; ++i)
    if (a.cycle[i] != b.cycle[(a.size - i) % a.size]) return false;
  return true;
}

bool same(const FaceUse& a, const FaceUse& b) {
  return a.cycle == b.cycle;
}

}  // namespace

std::string MeshCheck::describe() const {
  return fmt::format(
      "nonpositive cells {}, unmatched faces {}, misoriented pairs {}, overshared faces {}, "
      "boundary mismatches {}, open boundary edges {}, unused nodes {}, Euler cells {} "
      "boundary {}, min volume {:.3g}",
      nonpositive_cells, unmatched_faces, misoriented_pairs, overshared_faces, boundary_mismatches,
      open_boundary_edges, unused_nodes, euler_cells, euler_boundary, min_volume);
}

MeshCheck check_mesh(const HybridMesh& m) {
  MeshCheck r;
  r.min_volume = std::numeric_limits<double>::infinity();
  std::vector<FaceUse> faces;
  faces.reserve(4 * m.tets.size() + 5 * m.pyramids.size() + 6 * m.hexes.size() +
                m.boundary_tris.size() + m.boundary_quads.size());
  std::vector<std::pair<NodeId, NodeId>> cell_edges;
  auto add_edge = [&](NodeId a, NodeId b) {
    cell_edges.push_back({std::min(a, b), std::max(a, b)});
  };
  auto note_volume = [&](double v) {
    r.min_volume = std::min(r.min_volume, v);
    if (!(v > 0.0)) ++r.nonpositive_cells;
  };
  // A cell's faces from the shared tables; its edges are those of its faces (duplicates go
  // when the edges are sorted).
  auto add_cell = [&](const auto& c) {
    for (const auto& f : cell_faces(static_cast<int>(c.size()))) {
      NodeId n[4];
      for (int k = 0; k < f.size; ++k) n[k] = c[f.v[k]];
      faces.push_back(make_face(n, f.size, 0));
      for (int k = 0; k < f.size; ++k) add_edge(n[k], n[(k + 1) % f.size]);
    }
  };
  for (const auto& t : m.tets) {
    note_volume(tet_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]));
    add_cell(t);
  }
  for (const auto& p : m.pyramids) {
    // Every sub-tetrahedron of both diagonal splits must be positive for a valid pyramid.
    const auto& x = m.nodes;
    note_volume(std::min({tet_volume(x[p[0]], x[p[1]], x[p[2]], x[p[4]]),
                          tet_volume(x[p[0]], x[p[2]], x[p[3]], x[p[4]]),
                          tet_volume(x[p[0]], x[p[1]], x[p[3]], x[p[4]]),
                          tet_volume(x[p[1]], x[p[2]], x[p[3]], x[p[4]])}));
    add_cell(p);
  }
  for (const auto& h : m.hexes) {
    note_volume(hex_volume(m, h));
    add_cell(h);
  }
  std::vector<std::pair<NodeId, NodeId>> boundary_edges;
  for (const auto& t : m.boundary_tris) {
    faces.push_back(make_face(t.data(), 3, 1));
    for (int a = 0; a < 3; ++a)
      boundary_edges.push_back({std::min(t[a], t[(a + 1) % 3]), std::max(t[a], t[(a + 1) % 3])});
  }
  for (const auto& q : m.boundary_quads) {
    faces.push_back(make_face(q.data(), 4, 1));
    for (int a = 0; a < 4; ++a)
      boundary_edges.push_back({std::min(q[a], q[(a + 1) % 4]), std::max(q[a], q[(a + 1) % 4])});
  }

  std::sort(faces.begin(), faces.end(), [](const FaceUse& a, const FaceUse& b) {
    return a.key != b.key ? a.key < b.key : a.source < b.source;
  });
  long unique_cell_faces = 0;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    int cells = 0, bnd = 0;
    for (std::size_t n = i; n < j; ++n) (faces[n].source ? bnd : cells)++;
    if (cells > 0) ++unique_cell_faces;
    if (cells > 2) ++r.overshared_faces;
    if (cells == 2) {
      if (!reversed(faces[i], faces[i + 1])) ++r.misoriented_pairs;
      r.boundary_mismatches += static_cast<std::size_t>(bnd);
    } else if (cells == 1) {
      if (bnd == 0)
        ++r.unmatched_faces;
      else if (bnd > 1 || !same(faces[i], faces[i + 1]))
        ++r.boundary_mismatches;
    } else if (cells == 0) {
      r.boundary_mismatches += static_cast<std::size_t>(bnd);
    }
    i = j;
  }

  std::sort(boundary_edges.begin(), boundary_edges.end());
  long unique_boundary_edges = 0;
  for (std::size_t i = 0; i < boundary_edges.size();) {
    std::size_t j = i;
    while (j < boundary_edges.size() && boundary_edges[j] == boundary_edges[i]) ++j;
    if (j - i != 2) ++r.open_boundary_edges;
    ++unique_boundary_edges;
    i = j;
  }
  std::sort(cell_edges.begin(), cell_edges.end());
  const long unique_cell_edges =
      std::unique(cell_edges.begin(), cell_edges.end()) - cell_edges.begin();

  std::vector<char> used(m.nodes.size(), 0), on_boundary(m.nodes.size(), 0);
  auto mark = [&](const auto& cells, std::vector<char>& flag) {
    for (const auto& c : cells)
      for (NodeId n : c) flag[n] = 1;
  };
  mark(m.tets, used);
  mark(m.pyramids, used);
  mark(m.hexes, used);
  mark(m.boundary_tris, on_boundary);
  mark(m.boundary_quads, on_boundary);
  const long nodes_used = std::count(used.begin(), used.end(), 1);
  r.unused_nodes = m.nodes.size() - static_cast<std::size_t>(nodes_used);
  r.euler_cells =
      nodes_used - unique_cell_edges + unique_cell_faces - static_cast<long>(m.cell_count());
  r.euler_boundary = std::count(on_boundary.begin(), on_boundary.end(), 1) - unique_boundary_edges +
                     static_cast<long>(m.boundary_tris.size() + m.boundary_quads.size());
  if (m.cell_count() == 0) r.min_volume = 0.0;
  return r;
}

}  // namespace naris
