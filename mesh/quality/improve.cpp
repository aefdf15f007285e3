#include "mesh/quality/improve.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <span>
#include <unordered_map>

#include "core/log.h"
#include "mesh/quality/node_incidence.h"

namespace naris {
namespace {

using Vec = Eigen::Vector3d;

struct Cell {
  std::uint8_t size = 0;  // 4, 5, 8; 0 when removed
  std::array<NodeId, 8> v{};
};

struct Face {
  std::uint8_t size = 0;  // 3, 4; 0 when removed
  std::array<NodeId, 4> v{};
  std::int32_t patch = 0;
};

// node → incident items, as a compressed table plus lists gained by merges.
class Incidence {
 public:
  template <class Items>
  void build(std::size_t nodes, const Items& items) {
    table_.build(nodes, items.size(), [&](std::size_t i) {
      return std::span<const NodeId>(items[i].v.data(), items[i].size);
    });
  }
  template <class F>
  void for_each(NodeId n, F&& f) const {
    for (auto i : table_.of(n)) f(i);
    if (const auto it = extra_.find(n); it != extra_.end())
      for (auto i : it->second) f(i);
  }
  void add(NodeId n, std::int32_t item) { extra_[n].push_back(item); }
  void merge(NodeId from, NodeId into) {
    auto& dst = extra_[into];
    for_each(from, [&](std::int32_t i) { dst.push_back(i); });
  }

 private:
  NodeIncidence table_;
  std::unordered_map<NodeId, std::vector<std::int32_t>> extra_;
};

bool has(const Cell& c, NodeId n) {
  return std::find(c.v.begin(), c.v.begin() + c.size, n) != c.v.begin() + c.size;
}
bool has(const Face& f, NodeId n) {
  return std::find(f.v.begin(), f.v.begin() + f.size, n) != f.v.begin() + f.size;
}
// a–b is one of the face's edges (not a quadrilateral's diagonal).
bool has_edge(const Face& f, NodeId a, NodeId b) {
  for (int k = 0; k < f.size; ++k) {
    const NodeId p = f.v[k], q = f.v[(k + 1) % f.size];
    if ((p == a && q == b) || (p == b && q == a)) return true;
  }
  return false;
}

double tet6(const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  return (b - a).cross(c - a).dot(d - a);
}

// Scaled Jacobian of a tetrahedron, pyramid or hexahedron, ≤ 0 when inverted.
double cell_shape(const Cell& c, const std::vector<Vec>& x) {
  // The lowest corner, scaled so that the regular tetrahedron's and the cube's are 1.
  auto lowest = [&](const auto& corners, double scale) {
    double worst = INFINITY;
    for (const auto& k : corners) {
      const Vec e1 = x[c.v[k[1]]] - x[c.v[k[0]]], e2 = x[c.v[k[2]]] - x[c.v[k[0]]],
                e3 = x[c.v[k[3]]] - x[c.v[k[0]]];
      const double norms = e1.norm() * e2.norm() * e3.norm();
      worst = std::min(worst, norms > 0.0 ? e1.cross(e2).dot(e3) / norms * scale : -1.0);
    }
    return worst;
  };
  if (c.size == 4) return lowest(kTetCorners, std::numbers::sqrt2);
  if (c.size == 8) return lowest(kHexCorners, 1.0);
  // Pyramid: base corners, and every sub-tetrahedron of both base diagonals must be positive.
  const auto& v = c.v;
  const double tets = std::min(
      {tet6(x[v[0]], x[v[1]], x[v[2]], x[v[4]]), tet6(x[v[0]], x[v[2]], x[v[3]], x[v[4]]),
       tet6(x[v[0]], x[v[1]], x[v[3]], x[v[4]]), tet6(x[v[1]], x[v[2]], x[v[3]], x[v[4]])});
  if (!(tets > 0.0)) return -1.0;
  return lowest(kPyramidCorners, std::numbers::sqrt2);
}

Vec face_normal(const Face& f, const std::vector<Vec>& x) {
  if (f.size == 3) return (x[f.v[1]] - x[f.v[0]]).cross(x[f.v[2]] - x[f.v[0]]);
  return (x[f.v[2]] - x[f.v[0]]).cross(x[f.v[3]] - x[f.v[1]]);
}

// A cell or boundary face after collapsing b into a (a survives). Where only b is present it
// is renamed; where both are, a simplex (tetrahedron, triangle) degenerates away (size 0),
// while a pyramid or a quadrilateral drops b from its base: the pyramid becomes a tetrahedron
// (base order kept, apex last), the quadrilateral a triangle.
template <class Item>
Item collapsed(const Item& item, NodeId a, NodeId b, int simplex) {
  Item out = item;
  if (!has(item, b)) return out;
  if (!has(item, a)) {
    std::replace(out.v.begin(), out.v.begin() + item.size, b, a);
    return out;
  }
  if (item.size == simplex) {
    out.size = 0;
    return out;
  }
  int k = 0;
  for (int i = 0; i < item.size; ++i)
    if (item.v[i] != b) out.v[k++] = item.v[i];
  out.size = static_cast<std::uint8_t>(item.size - 1);
  return out;
}
Cell collapsed(const Cell& c, NodeId a, NodeId b) {
  return collapsed(c, a, b, 4);
}
Face collapsed(const Face& f, NodeId a, NodeId b) {
  return collapsed(f, a, b, 3);
}

}  // namespace

ImproveStats improve_mesh(HybridMesh& mesh, double voxel_size, const ImproveOptions& options,
                          std::vector<std::int64_t>* unchanged_from) {
  Stopwatch clock;
  ImproveStats stats;
  const double min_edge = options.min_edge_fraction * voxel_size;
  const std::size_t n_nodes = mesh.nodes.size();
  std::vector<Vec> x(mesh.nodes.begin(), mesh.nodes.end());

  std::vector<Cell> cells;
  cells.reserve(mesh.cell_count());
  for (const auto& t : mesh.tets) cells.push_back({4, {t[0], t[1], t[2], t[3]}});
  for (const auto& p : mesh.pyramids) cells.push_back({5, {p[0], p[1], p[2], p[3], p[4]}});
  std::vector<char> locked(n_nodes, 0);
  for (const auto& h : mesh.hexes) {
    Cell c{8, {}};
    std::copy(h.begin(), h.end(), c.v.begin());
    cells.push_back(c);
    for (NodeId n : h) locked[n] = 1;
  }
  std::vector<Face> faces;
  faces.reserve(mesh.boundary_tris.size() + mesh.boundary_quads.size());
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f) {
    const auto& t = mesh.boundary_tris[f];
    faces.push_back({3, {t[0], t[1], t[2], 0}, mesh.boundary_tri_patch[f]});
  }
  for (std::size_t f = 0; f < mesh.boundary_quads.size(); ++f) {
    const auto& q = mesh.boundary_quads[f];
    faces.push_back({4, {q[0], q[1], q[2], q[3]}, mesh.boundary_quad_patch[f]});
  }
  // A node's patch: -1 interior, ≥ 0 one patch, -2 on a line between patches. A line node's two
  // patches (both -2 where three or more meet).
  std::vector<std::int32_t> patch(n_nodes, -1);
  std::vector<std::array<std::int32_t, 2>> line(n_nodes, {-1, -1});
  for (const auto& f : faces)
    for (int k = 0; k < f.size; ++k) {
      const NodeId n = f.v[k];
      auto& p = patch[n];
      if (p != -1 && p != f.patch && p != -2)
        line[n] = {std::min(p, f.patch), std::max(p, f.patch)};
      if (p == -2 && f.patch != line[n][0] && f.patch != line[n][1]) line[n] = {-2, -2};
      p = p == -1 || p == f.patch ? f.patch : -2;
    }

  // Candidates: short edges of tetrahedra and pyramids, shortest first.
  std::vector<std::tuple<double, NodeId, NodeId>> edges;
  for (const auto& c : cells) {
    if (c.size == 8) continue;
    auto consider = [&](NodeId a, NodeId b) {
      const double len = (x[a] - x[b]).norm();
      if (len < min_edge) edges.emplace_back(len, std::min(a, b), std::max(a, b));
    };
    for (const auto& e : cell_edges(c.size)) consider(c.v[e[0]], c.v[e[1]]);
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  stats.short_edges = edges.size();
  if (edges.empty()) {
    if (unchanged_from) {
      unchanged_from->resize(mesh.cell_count());
      std::iota(unchanged_from->begin(), unchanged_from->end(), std::int64_t{0});
    }
    return stats;
  }

  std::vector<char> changed(cells.size(), 0);  // in shape or position
  Incidence node_cells, node_faces;
  node_cells.build(n_nodes, cells);
  node_faces.build(n_nodes, faces);
  std::vector<NodeId> alias(n_nodes);
  for (std::size_t n = 0; n < n_nodes; ++n) alias[n] = static_cast<NodeId>(n);
  auto find = [&](NodeId n) {
    while (alias[n] != n) n = alias[n] = alias[alias[n]];
    return n;
  };

  std::vector<std::int32_t> around_a, around_b;
  std::vector<std::pair<NodeId, NodeId>> link_a, link_b, allowed_edges;
  // Edges of the faces around n that do not touch n: the edge part of n's link.
  auto link_edges = [&](NodeId n, const std::vector<std::int32_t>& around,
                        std::vector<std::pair<NodeId, NodeId>>& out) {
    out.clear();
    for (auto c : around) {
      const Cell& cell = cells[c];
      for (const auto& f : cell_faces(cell.size)) {
        bool touches = false;
        for (int k = 0; k < f.size; ++k) touches = touches || cell.v[f.v[k]] == n;
        if (!touches) continue;
        for (int k = 0; k < f.size; ++k) {
          const NodeId p = cell.v[f.v[k]], q = cell.v[f.v[(k + 1) % f.size]];
          if (p != n && q != n) out.push_back({std::min(p, q), std::max(p, q)});
        }
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  };
  std::vector<NodeId> neighbours_a, neighbours_b, allowed;
  // The distinct boundary faces on edge p–q (a node's list may hold a merged face twice).
  std::vector<std::int32_t> on_edge, around_edge;
  auto edge_faces = [&](NodeId p, NodeId q, std::vector<std::int32_t>& out) {
    out.clear();
    node_faces.for_each(p, [&](std::int32_t f) {
      if (faces[f].size && has_edge(faces[f], p, q) &&
          std::find(out.begin(), out.end(), f) == out.end())
        out.push_back(f);
    });
  };
  // The nodes joined to n by an edge of its line: an edge whose boundary faces are of both the
  // line's patches.
  auto line_neighbours = [&](NodeId n, std::vector<NodeId>& out) {
    out.clear();
    node_faces.for_each(n, [&](std::int32_t f) {
      const Face& face = faces[f];
      if (!face.size || !has(face, n)) return;
      for (int k = 0; k < face.size; ++k) {
        if (face.v[k] != n) continue;
        for (const NodeId m :
             {face.v[(k + 1) % face.size], face.v[(k + face.size - 1) % face.size]}) {
          edge_faces(n, m, around_edge);
          bool first = false, second = false;
          for (auto g : around_edge) {
            first = first || faces[g].patch == line[n][0];
            second = second || faces[g].patch == line[n][1];
          }
          if (first && second && std::find(out.begin(), out.end(), m) == out.end())
            out.push_back(m);
        }
      }
    });
  };
  // A split pyramid: its slot, itself, its slot's changed flag, the slot of its second half.
  std::vector<std::tuple<std::int32_t, Cell, char, std::int32_t>> saved_cells;
  std::vector<std::pair<std::int32_t, Face>> saved_faces;
  for (const auto& [len0, a0, b0] : edges) {
    NodeId a = find(a0), b = find(b0);
    if (a == b || (x[a] - x[b]).norm() >= min_edge) continue;
    // Which node survives (a), and where. Nodes on a line between patches move only along it
    // (below). A movable node merges into a fixed one at the fixed position; two movable nodes
    // meet at their midpoint. A boundary node merging into a hexahedron's interior node (a lattice
    // vertex) takes it onto the boundary where the boundary node stands: the wall stays on its
    // surface, and the hexahedra at the vertex warp by less than the edge (the lattice warp of
    // isosurface stuffing). Hexahedra without such a vertex never change.
    auto movable = [&](NodeId n) { return !locked[n] && patch[n] != -2; };
    // p and q on the line between the same two patches.
    auto one_line = [&](NodeId p, NodeId q) { return line[p][0] >= 0 && line[p] == line[q]; };
    // Two nodes of one line joined by a boundary edge merge at one of them (not a hexahedron's):
    // along the line where the edge is the line's, or across the ear of a patch that a chord
    // cuts off. A cut plane's rim keeps its shape.
    bool along_line = false;
    if (one_line(a, b) && !(locked[a] && locked[b])) {
      // Two faces on a boundary edge; a third one rules the edge out.
      edge_faces(a, b, on_edge);
      along_line = on_edge.size() == 2;
      // A chord (both faces one patch's) only where it cuts off an ear: a and b have a common
      // neighbour along the line, the ear's tip. Between two stretches of the line it would
      // pinch the patch.
      if (along_line && faces[on_edge[0]].patch == faces[on_edge[1]].patch) {
        line_neighbours(a, neighbours_a);
        line_neighbours(b, neighbours_b);
        bool ear = false;
        for (NodeId n : neighbours_a)
          ear = ear || std::find(neighbours_b.begin(), neighbours_b.end(), n) != neighbours_b.end();
        along_line = ear;
      }
      if (along_line && locked[b]) std::swap(a, b);
    }
    // A node of a line between patches merges into a hexahedron node on one of those patches
    // (a collapse made the lattice vertex a node of a cut plane): the line then passes the vertex.
    auto into_vertex_of = [&](NodeId p, NodeId q) {
      return locked[p] && !locked[q] && patch[q] == -2 && line[q][0] >= 0 && patch[p] >= 0 &&
             (patch[p] == line[q][0] || patch[p] == line[q][1]);
    };
    bool into_vertex = false;
    if (!along_line) {
      if (into_vertex_of(b, a)) std::swap(a, b);
      into_vertex = into_vertex_of(a, b);
    }
    if (!along_line && !into_vertex && !movable(a) && !movable(b)) {
      ++stats.refused_topology;
      continue;
    }
    if (!along_line && movable(a) && !movable(b))
      std::swap(a, b);
    else if (!along_line && movable(a) && movable(b) && patch[a] == -1 && patch[b] >= 0)
      std::swap(a, b);
    // Now b moves; a stays unless both are movable with the same patch.
    if (patch[a] >= 0 && patch[b] >= 0 && patch[a] != patch[b]) {
      ++stats.refused_topology;
      continue;
    }
    const bool midpoint = movable(a) && movable(b) && patch[a] == patch[b];
    const bool warp = locked[a] && patch[a] == -1 && !locked[b] && patch[b] >= 0;
    const Vec target = midpoint ? Vec(0.5 * (x[a] + x[b])) : warp ? x[b] : x[a];

    auto gather = [&](NodeId n, std::vector<std::int32_t>& around) {
      around.clear();
      node_cells.for_each(n, [&](std::int32_t c) {
        if (cells[c].size && has(cells[c], n)) around.push_back(c);
      });
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
    };
    gather(a, around_a);
    gather(b, around_b);
    // A pyramid with ab as a lateral edge is split first: into two tetrahedra along the base
    // diagonal through its base corner on ab, and so is what lies across its base (a pyramid, or
    // the boundary's quadrilateral; not a hexahedron). Undone if the collapse is refused.
    saved_cells.clear();
    saved_faces.clear();
    const std::size_t cells_before_split = cells.size(), faces_before_split = faces.size();
    auto add_cell = [&](const Cell& c) {
      cells.push_back(c);
      changed.push_back(1);
      for (int k = 0; k < c.size; ++k)
        node_cells.add(c.v[k], static_cast<std::int32_t>(cells.size() - 1));
    };
    // Item `slot` (a pyramid or a quadrilateral) split along the diagonal through `corner`: the
    // half with the corner's successor stays in the slot, the other is added.
    auto split_cell = [&](std::int32_t slot, NodeId corner) {
      const Cell p = cells[slot];
      saved_cells.push_back({slot, p, changed[slot], static_cast<std::int32_t>(cells.size())});
      const int k = static_cast<int>(std::find(p.v.begin(), p.v.begin() + 4, corner) - p.v.begin());
      const NodeId v0 = p.v[k], v1 = p.v[(k + 1) % 4], v2 = p.v[(k + 2) % 4], v3 = p.v[(k + 3) % 4];
      cells[slot] = {4, {v0, v1, v2, p.v[4]}};
      changed[slot] = 1;
      add_cell({4, {v0, v2, v3, p.v[4]}});
    };
    auto split_face = [&](std::int32_t slot, NodeId corner) {
      const Face q = faces[slot];
      saved_faces.push_back({slot, q});
      const int k = static_cast<int>(std::find(q.v.begin(), q.v.begin() + 4, corner) - q.v.begin());
      const NodeId v0 = q.v[k], v1 = q.v[(k + 1) % 4], v2 = q.v[(k + 2) % 4], v3 = q.v[(k + 3) % 4];
      faces[slot] = {3, {v0, v1, v2, 0}, q.patch};
      faces.push_back({3, {v0, v2, v3, 0}, q.patch});
      for (NodeId n : {v0, v2, v3}) node_faces.add(n, static_cast<std::int32_t>(faces.size() - 1));
    };
    bool split_refused = false;
    for (auto c : around_b) {
      const Cell p = cells[c];
      if (p.size != 5 || !has(p, a) || (p.v[4] != a && p.v[4] != b)) continue;
      const NodeId corner = p.v[4] == a ? b : a;
      auto holds_base = [&](const auto& item) {
        int count = 0;
        for (int k = 0; k < 4; ++k) count += has(item, p.v[k]);
        return count == 4;
      };
      std::int32_t across = -1, quad = -1;
      node_cells.for_each(corner, [&](std::int32_t q) {
        if (q != c && cells[q].size && holds_base(cells[q])) across = q;
      });
      node_faces.for_each(corner, [&](std::int32_t f) {
        if (faces[f].size == 4 && holds_base(faces[f])) quad = f;
      });
      const bool base_across =
          across >= 0 && cells[across].size == 5 &&
          std::find(p.v.begin(), p.v.begin() + 4, cells[across].v[4]) == p.v.begin() + 4;
      if (across >= 0 ? !base_across : quad < 0) {
        split_refused = true;
        break;
      }
      split_cell(c, corner);
      if (across >= 0)
        split_cell(across, corner);
      else
        split_face(quad, corner);
    }
    auto undo_split = [&]() {
      for (const auto& [slot, cell, was_changed, half] : saved_cells) {
        cells[slot] = cell;
        changed[slot] = was_changed;
      }
      for (const auto& [slot, face] : saved_faces) faces[slot] = face;
      for (std::size_t c = cells_before_split; c < cells.size(); ++c) cells[c].size = 0;
      for (std::size_t f = faces_before_split; f < faces.size(); ++f) faces[f].size = 0;
    };
    if (split_refused) {
      undo_split();
      ++stats.refused_topology;
      continue;
    }
    if (!saved_cells.empty()) {
      gather(a, around_a);
      gather(b, around_b);
    }

    // Topology: the cells on the edge, the pyramid rules, and the link condition.
    bool ok = true;
    allowed.clear();
    for (auto c : around_b) {
      const Cell& cell = cells[c];
      if (!has(cell, a)) continue;
      if (cell.size == 8) ok = false;
      if (cell.size == 5 && (cell.v[4] == a || cell.v[4] == b)) ok = false;  // lateral edge
      if (cell.size == 4) {
        for (int k = 0; k < 4; ++k)
          if (cell.v[k] != a && cell.v[k] != b) allowed.push_back(cell.v[k]);
      } else if (cell.size == 5) {
        allowed.push_back(cell.v[4]);
      }
    }
    auto neighbours = [&](NodeId n, const std::vector<std::int32_t>& around,
                          std::vector<NodeId>& out) {
      out.clear();
      for (auto c : around) {
        const Cell& cell = cells[c];
        for (int k = 0; k < cell.size; ++k)
          if (cell.v[k] != n) out.push_back(cell.v[k]);
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    };
    // Edge part of the link condition: an edge in both links must lie in a cell on edge ab.
    if (ok) {
      link_edges(a, around_a, link_a);
      link_edges(b, around_b, link_b);
      allowed_edges.clear();
      for (auto c : around_b) {
        const Cell& cell = cells[c];
        if (!has(cell, a)) continue;
        for (const auto& f : cell_faces(cell.size))
          for (int k = 0; k < f.size; ++k) {
            const NodeId p = cell.v[f.v[k]], q = cell.v[f.v[(k + 1) % f.size]];
            if (p != a && p != b && q != a && q != b)
              allowed_edges.push_back({std::min(p, q), std::max(p, q)});
          }
      }
      std::sort(allowed_edges.begin(), allowed_edges.end());
      for (const auto& e : link_a)
        if (std::binary_search(link_b.begin(), link_b.end(), e) &&
            !std::binary_search(allowed_edges.begin(), allowed_edges.end(), e)) {
          ok = false;
          break;
        }
    }
    if (ok) {
      neighbours(a, around_a, neighbours_a);
      neighbours(b, around_b, neighbours_b);
      std::sort(allowed.begin(), allowed.end());
      for (NodeId c : neighbours_a) {
        if (c == b) continue;
        if (std::binary_search(neighbours_b.begin(), neighbours_b.end(), c) &&
            !std::binary_search(allowed.begin(), allowed.end(), c)) {
          ok = false;
          break;
        }
      }
    }
    // Two boundary nodes joined by an interior edge: collapsing would pinch the domain. On the
    // boundary surface the link condition must hold too: the only boundary nodes adjacent to
    // both a and b are the third corners of the boundary triangles on edge ab.
    if (ok && patch[a] != -1 && patch[b] != -1) {
      bool boundary_edge = false;
      allowed.clear();
      auto surface_neighbours = [&](NodeId n, std::vector<NodeId>& out) {
        out.clear();
        node_faces.for_each(n, [&](std::int32_t f) {
          const Face& face = faces[f];
          if (!face.size || !has(face, n)) return;
          if (n == b && has(face, a)) {
            boundary_edge = true;
            if (face.size == 3)
              for (int k = 0; k < 3; ++k)
                if (face.v[k] != a && face.v[k] != b) allowed.push_back(face.v[k]);
          }
          for (int k = 0; k < face.size; ++k) {
            // Neighbours along the face's edges only (not across a quadrilateral's diagonal).
            const NodeId prev = face.v[(k + face.size - 1) % face.size],
                         next = face.v[(k + 1) % face.size];
            if (face.v[k] == n) {
              out.push_back(prev);
              out.push_back(next);
            }
          }
        });
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
      };
      surface_neighbours(a, neighbours_a);
      surface_neighbours(b, neighbours_b);
      ok = boundary_edge;
      std::sort(allowed.begin(), allowed.end());
      for (NodeId c : neighbours_a)
        if (ok && c != b && std::binary_search(neighbours_b.begin(), neighbours_b.end(), c) &&
            !std::binary_search(allowed.begin(), allowed.end(), c))
          ok = false;
    }
    if (!ok) {
      undo_split();
      ++stats.refused_topology;
      continue;
    }

    // Geometry: every changed cell stays well shaped, no boundary face flips.
    const Vec xa = x[a], xb = x[b];
    x[a] = target;
    x[b] = target;
    // A changed cell must stay valid, and may fall below the quality floor only if it was
    // already worse before the collapse, or if it is the next collapse's (below).
    auto acceptable = [&](const Cell& before, const Cell& after) {
      const double now = cell_shape(after, x);
      if (!(now > 0.0)) return false;
      if (now >= options.min_scaled_jacobian) return true;
      // A cell left with another short edge at the merged node that a collapse may take (not a
      // pyramid's lateral edge, the other end movable or on a's line) is the next collapse's: a
      // cluster of isopoints near one lattice vertex (a cut plane passing it) goes edge by edge.
      // Not after a warp: its flat cells lie on the wall, where the next collapse is often
      // refused, and would stay flat.
      const auto& edges_of = cell_edges(after.size);
      for (std::size_t k = 0; !warp && k < edges_of.size(); ++k) {
        const NodeId p = after.v[edges_of[k][0]], q = after.v[edges_of[k][1]];
        if (p != a && q != a) continue;
        const NodeId other = p == a ? q : p;
        const bool lateral = after.size == 5 && (edges_of[k][0] == 4 || edges_of[k][1] == 4);
        const bool collapsible = movable(other) || one_line(a, other);
        if (!lateral && collapsible && (x[p] - x[q]).norm() < min_edge) return true;
      }
      x[a] = xa;
      x[b] = xb;
      const double old = cell_shape(before, x);
      x[a] = target;
      x[b] = target;
      return now >= old;
    };
    bool shaped = true;
    for (auto c : around_b) {
      const Cell after = collapsed(cells[c], a, b);
      if (after.size == 8)
        shaped = false;
      else if (after.size && !acceptable(cells[c], after))
        shaped = false;
    }
    if (shaped && target != xa)
      for (auto c : around_a) {
        const Cell& cell = cells[c];
        if (has(cell, b)) continue;
        if (!acceptable(cell, cell)) shaped = false;
      }
    // The halves of a split pyramid, measured against the pyramid (one may touch neither a nor b).
    for (const auto& [slot, pyramid, was_changed, half] : saved_cells)
      for (const std::int32_t c : {slot, half}) {
        const Cell after = collapsed(cells[c], a, b);
        if (after.size && !acceptable(pyramid, after)) shaped = false;
      }
    if (shaped) {
      auto flips = [&](NodeId n) {
        bool flipped = false;
        node_faces.for_each(n, [&](std::int32_t f) {
          if (!faces[f].size || !has(faces[f], n)) return;
          const Face after = collapsed(faces[f], a, b);
          if (!after.size) return;
          // Normal before (original positions) against normal after.
          x[a] = xa;
          x[b] = xb;
          const Vec before = face_normal(faces[f], x);
          x[a] = target;
          x[b] = target;
          const Vec now = face_normal(after, x);
          if (!(now.dot(before) > 0.5 * now.norm() * before.norm())) flipped = true;
        });
        return flipped;
      };
      shaped = !flips(a) && !flips(b);
    }
    if (!shaped) {
      x[a] = xa;
      x[b] = xb;
      undo_split();
      ++stats.refused_geometry;
      continue;
    }

    // Apply.
    for (auto c : around_a) changed[c] = 1;
    for (auto c : around_b) {
      changed[c] = 1;
      const Cell before = cells[c];
      cells[c] = collapsed(before, a, b);
      if (!cells[c].size)
        ++stats.removed_cells;
      else if (before.size == 5 && cells[c].size == 4)
        ++stats.pyramids_to_tets;
    }
    node_faces.for_each(b, [&](std::int32_t f) {
      if (faces[f].size && has(faces[f], b)) faces[f] = collapsed(faces[f], a, b);
    });
    node_cells.merge(b, a);
    node_faces.merge(b, a);
    alias[b] = a;
    if (patch[a] == -1 || into_vertex) patch[a] = patch[b];
    if (into_vertex) line[a] = line[b];
    ++stats.collapsed;
    stats.pyramids_split += saved_cells.size();
    stats.vertices_warped += warp;
  }

  // Back to the mesh arrays.
  for (std::size_t n = 0; n < n_nodes; ++n) mesh.nodes[n] = x[n];
  mesh.tets.clear();
  mesh.pyramids.clear();
  mesh.hexes.clear();
  // Cells keep their type order (tets, pyramids, hexes) and, within a type, their order; a
  // pyramid turned tetrahedron joins the tetrahedra.
  if (unchanged_from) {
    unchanged_from->clear();
    for (int size : {4, 5, 8})
      for (std::size_t c = 0; c < cells.size(); ++c)
        if (cells[c].size == size)
          unchanged_from->push_back(changed[c] ? -1 : static_cast<std::int64_t>(c));
  }
  for (const auto& c : cells) {
    if (c.size == 4)
      mesh.tets.push_back({c.v[0], c.v[1], c.v[2], c.v[3]});
    else if (c.size == 5)
      mesh.pyramids.push_back({c.v[0], c.v[1], c.v[2], c.v[3], c.v[4]});
    else if (c.size == 8)
      mesh.hexes.push_back({c.v[0], c.v[1], c.v[2], c.v[3], c.v[4], c.v[5], c.v[6], c.v[7]});
  }
  mesh.boundary_tris.clear();
  mesh.boundary_tri_patch.clear();
  mesh.boundary_quads.clear();
  mesh.boundary_quad_patch.clear();
  for (const auto& f : faces) {
    if (f.size == 3) {
      mesh.boundary_tris.push_back({f.v[0], f.v[1], f.v[2]});
      mesh.boundary_tri_patch.push_back(f.patch);
    } else if (f.size == 4) {
      mesh.boundary_quads.push_back({f.v[0], f.v[1], f.v[2], f.v[3]});
      mesh.boundary_quad_patch.push_back(f.patch);
    }
  }
  compact_nodes(mesh);
  stats.seconds = clock.seconds();
  return stats;
}

}  // namespace naris
