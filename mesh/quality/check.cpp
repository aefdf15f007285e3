#include "mesh/quality/check.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <mutex>
#include <vector>

#include "core/parallel.h"

namespace naris {
namespace {

constexpr NodeId kNone = std::numeric_limits<NodeId>::max();

// One use of a face, filed under its smallest node m, as a sortable key: the other nodes, in an
// order fixed by the node set and the diagonal (a triangle m-a-b: min, max, kNone; a
// quadrilateral m-a-b-c: min(a, c), b, max(a, c)), then flags, packed in two 64-bit words
// (node ids are non-negative). The flags' bit 0 is the orientation (a < b, resp. a < c), bit 1
// set for the boundary list's faces, so that the uses of one face sort cells first.
using FaceUse = std::pair<std::uint64_t, std::uint64_t>;

FaceUse pack(NodeId x, NodeId y, NodeId z, int flags) {
  return {std::uint64_t(std::uint32_t(x)) << 32 | std::uint32_t(y),
          std::uint64_t(std::uint32_t(z)) << 32 | std::uint32_t(flags)};
}

FaceUse face_use(const NodeId* n, int size, int start, int listed) {
  const NodeId a = n[(start + 1) % size], b = n[(start + 2) % size];
  if (size == 3) return pack(std::min(a, b), std::max(a, b), kNone, (a < b) | listed << 1);
  const NodeId c = n[(start + 3) % size];
  return pack(std::min(a, c), b, std::max(a, c), (a < c) | listed << 1);
}

bool same_face(const FaceUse& a, const FaceUse& b) {
  return a.first == b.first && a.second >> 32 == b.second >> 32;
}
int orientation(const FaceUse& f) {
  return static_cast<int>(f.second & 1);
}
bool is_listed(const FaceUse& f) {
  return (f.second & 2) != 0;
}

// Insertion sort: the lists under one node are short.
template <class T>
void sort_short(T* first, T* last) {
  if (last - first > 32) return std::sort(first, last);
  for (T* i = first + 1; i < last; ++i)
    for (T* j = i; j > first && *j < j[-1]; --j) std::swap(*j, j[-1]);
}

// Calls the visitor for every use of a face or an edge, and every node of a cell or of the
// boundary, whose smallest node lies in [lo, hi).
template <class Visitor>
void visit_uses(const HybridMesh& m, NodeId lo, NodeId hi, Visitor& v) {
  auto in = [&](NodeId n) { return n >= lo && n < hi; };
  auto cells = [&](const auto& list) {
    for (const auto& c : list) {
      const auto [low, high] = std::minmax_element(c.begin(), c.end());
      if (*low >= hi || *high < lo) continue;  // nothing of this cell is filed in the range
      for (NodeId n : c)
        if (in(n)) v.used(n);
      for (const auto& f : cell_faces(static_cast<int>(c.size()))) {
        int start = 0;
        for (int k = 1; k < f.size; ++k)
          if (c[f.v[k]] < c[f.v[start]]) start = k;
        if (!in(c[f.v[start]])) continue;
        NodeId n[4];
        for (int k = 0; k < f.size; ++k) n[k] = c[f.v[k]];
        v.face(n, f.size, start, 0);
      }
      for (const auto& e : cell_edges(static_cast<int>(c.size()))) {
        const NodeId a = c[e[0]], b = c[e[1]];
        if (in(std::min(a, b))) v.cell_edge(std::min(a, b), std::max(a, b));
      }
    }
  };
  cells(m.tets);
  cells(m.pyramids);
  cells(m.hexes);
  auto boundary = [&](const auto& list) {
    for (const auto& f : list) {
      const int size = static_cast<int>(f.size());
      int start = 0;
      for (int k = 0; k < size; ++k) {
        if (f[k] < f[start]) start = k;
        if (in(f[k])) v.on_boundary(f[k]);
        const NodeId a = f[k], b = f[(k + 1) % size];
        if (in(std::min(a, b))) v.boundary_edge(std::min(a, b), std::max(a, b));
      }
      if (in(f[start])) v.face(f.data(), size, start, 1);
    }
  };
  boundary(m.boundary_tris);
  boundary(m.boundary_quads);
}

// The uses filed under each node of one range, in compressed rows (offsets per node).
struct NodeRange {
  NodeId lo = 0, hi = 0;
  std::vector<std::size_t> face_row, edge_row, boundary_edge_row;
  std::vector<FaceUse> faces;
  std::vector<NodeId> edges, boundary_edges;  // the larger node of each edge use
  std::vector<char> used, on_boundary;
};

struct Counter {
  NodeRange& r;
  void used(NodeId n) { r.used[n - r.lo] = 1; }
  void on_boundary(NodeId n) { r.on_boundary[n - r.lo] = 1; }
  void face(const NodeId* n, int, int start, int) { ++r.face_row[n[start] - r.lo + 1]; }
  void cell_edge(NodeId a, NodeId) { ++r.edge_row[a - r.lo + 1]; }
  void boundary_edge(NodeId a, NodeId) { ++r.boundary_edge_row[a - r.lo + 1]; }
};

struct Filler {
  NodeRange& r;
  std::vector<std::size_t> face_at, edge_at, boundary_edge_at;
  void used(NodeId) {}
  void on_boundary(NodeId) {}
  void face(const NodeId* n, int size, int start, int listed) {
    r.faces[face_at[n[start] - r.lo]++] = face_use(n, size, start, listed);
  }
  void cell_edge(NodeId a, NodeId b) { r.edges[edge_at[a - r.lo]++] = b; }
  void boundary_edge(NodeId a, NodeId b) { r.boundary_edges[boundary_edge_at[a - r.lo]++] = b; }
};

void fill_range(const HybridMesh& m, NodeRange& r) {
  const std::size_t n = static_cast<std::size_t>(r.hi - r.lo);
  for (auto* row : {&r.face_row, &r.edge_row, &r.boundary_edge_row}) row->assign(n + 1, 0);
  r.used.assign(n, 0);
  r.on_boundary.assign(n, 0);
  Counter count{r};
  visit_uses(m, r.lo, r.hi, count);
  for (auto* row : {&r.face_row, &r.edge_row, &r.boundary_edge_row})
    for (std::size_t i = 0; i < n; ++i) (*row)[i + 1] += (*row)[i];
  r.faces.resize(r.face_row[n]);
  r.edges.resize(r.edge_row[n]);
  r.boundary_edges.resize(r.boundary_edge_row[n]);
  Filler fill{r, r.face_row, r.edge_row, r.boundary_edge_row};
  visit_uses(m, r.lo, r.hi, fill);
}

// The counts of one thread's cells and node ranges, summed over the threads.
struct Tally {
  MeshCheck check;
  long unique_cell_faces = 0, unique_cell_edges = 0, unique_boundary_edges = 0;
  long used_nodes = 0, boundary_nodes = 0;

  void add(const Tally& o) {
    MeshCheck& c = check;
    const MeshCheck& d = o.check;
    c.nonpositive_cells += d.nonpositive_cells;
    c.min_volume = std::min(c.min_volume, d.min_volume);
    c.unmatched_faces += d.unmatched_faces;
    c.misoriented_pairs += d.misoriented_pairs;
    c.overshared_faces += d.overshared_faces;
    c.boundary_mismatches += d.boundary_mismatches;
    c.open_boundary_edges += d.open_boundary_edges;
    unique_cell_faces += o.unique_cell_faces;
    unique_cell_edges += o.unique_cell_edges;
    unique_boundary_edges += o.unique_boundary_edges;
    used_nodes += o.used_nodes;
    boundary_nodes += o.boundary_nodes;
  }
};

void judge_range(NodeRange& r, Tally& t) {
  MeshCheck& c = t.check;
  const std::size_t n = static_cast<std::size_t>(r.hi - r.lo);
  for (std::size_t node = 0; node < n; ++node) {
    t.used_nodes += r.used[node];
    t.boundary_nodes += r.on_boundary[node];
    // Faces: the uses of one face are adjacent after sorting, cells before the boundary list.
    auto* first = r.faces.data() + r.face_row[node];
    auto* last = r.faces.data() + r.face_row[node + 1];
    sort_short(first, last);
    for (auto* i = first; i < last;) {
      auto* j = i;
      int cells = 0, listed = 0;
      for (; j < last && same_face(*j, *i); ++j) (is_listed(*j) ? listed : cells)++;
      const bool opposite = j - i >= 2 && orientation(i[0]) != orientation(i[1]);
      if (cells > 0) ++t.unique_cell_faces;
      if (cells > 2) ++c.overshared_faces;
      if (cells == 2) {
        if (!opposite) ++c.misoriented_pairs;
        c.boundary_mismatches += static_cast<std::size_t>(listed);
      } else if (cells == 1) {
        if (listed == 0)
          ++c.unmatched_faces;
        else if (listed > 1 || opposite)
          ++c.boundary_mismatches;
      } else {
        c.boundary_mismatches += static_cast<std::size_t>(listed);
      }
      i = j;
    }
    // Edges: distinct ones in the cells; each boundary edge on exactly two boundary faces.
    auto* e0 = r.edges.data() + r.edge_row[node];
    auto* e1 = r.edges.data() + r.edge_row[node + 1];
    sort_short(e0, e1);
    t.unique_cell_edges += std::unique(e0, e1) - e0;
    auto* b0 = r.boundary_edges.data() + r.boundary_edge_row[node];
    auto* b1 = r.boundary_edges.data() + r.boundary_edge_row[node + 1];
    sort_short(b0, b1);
    for (auto* i = b0; i < b1;) {
      auto* j = i;
      while (j < b1 && *j == *i) ++j;
      if (j - i != 2) ++c.open_boundary_edges;
      ++t.unique_boundary_edges;
      i = j;
    }
  }
}

// Node ranges small enough that one holds at most this many face uses (about 256 MB).
constexpr std::size_t kUsesPerRange = 16'000'000;

}  // namespace

std::string MeshCheck::describe() const {
  return fmt::format(
      "nonpositive cells {}, unmatched faces {}, misoriented pairs {}, overshared faces {}, "
      "boundary mismatches {}, open boundary edges {}, unused nodes {}, Euler cells {} "
      "boundary {}, min volume {:.3g}",
      nonpositive_cells, unmatched_faces, misoriented_pairs, overshared_faces, boundary_mismatches,
      open_boundary_edges, unused_nodes, euler_cells, euler_boundary, min_volume);
}

MeshCheck check_mesh(const HybridMesh& m, int threads) {
  const unsigned workers = thread_count(threads);
  const std::size_t uses = 4 * m.tets.size() + 5 * m.pyramids.size() + 6 * m.hexes.size() +
                           m.boundary_tris.size() + m.boundary_quads.size();
  const std::size_t per_worker = (uses / kUsesPerRange + workers) / workers;
  const std::size_t ranges = per_worker * workers;
  const auto nodes = static_cast<NodeId>(m.nodes.size());

  Tally total;
  total.check.min_volume = std::numeric_limits<double>::infinity();
  std::mutex lock;
  run_threads(workers, [&](unsigned t, unsigned count) {
    Tally mine;
    MeshCheck& c = mine.check;
    c.min_volume = std::numeric_limits<double>::infinity();
    auto note_volume = [&](double v) {
      c.min_volume = std::min(c.min_volume, v);
      if (!(v > 0.0)) ++c.nonpositive_cells;
    };
    const auto& x = m.nodes;
    for (auto [i, end] = share(m.tets.size(), t, count); i < end; ++i) {
      const auto& e = m.tets[i];
      note_volume(tet_volume(x[e[0]], x[e[1]], x[e[2]], x[e[3]]));
    }
    for (auto [i, end] = share(m.pyramids.size(), t, count); i < end; ++i) {
      // Every sub-tetrahedron of both diagonal splits must be positive for a valid pyramid.
      const auto& p = m.pyramids[i];
      note_volume(std::min({tet_volume(x[p[0]], x[p[1]], x[p[2]], x[p[4]]),
                            tet_volume(x[p[0]], x[p[2]], x[p[3]], x[p[4]]),
                            tet_volume(x[p[0]], x[p[1]], x[p[3]], x[p[4]]),
                            tet_volume(x[p[1]], x[p[2]], x[p[3]], x[p[4]])}));
    }
    for (auto [i, end] = share(m.hexes.size(), t, count); i < end; ++i)
      note_volume(hex_volume(m, m.hexes[i]));

    NodeRange range;
    for (std::size_t k = t; k < ranges; k += count) {
      const auto [lo, hi] = share(static_cast<std::size_t>(nodes), static_cast<unsigned>(k),
                                  static_cast<unsigned>(ranges));
      range.lo = static_cast<NodeId>(lo);
      range.hi = static_cast<NodeId>(hi);
      fill_range(m, range);
      judge_range(range, mine);
    }
    std::lock_guard guard(lock);
    total.add(mine);
  });

  MeshCheck r = total.check;
  r.unused_nodes = m.nodes.size() - static_cast<std::size_t>(total.used_nodes);
  r.euler_cells = total.used_nodes - total.unique_cell_edges + total.unique_cell_faces -
                  static_cast<long>(m.cell_count());
  r.euler_boundary = total.boundary_nodes - total.unique_boundary_edges +
                     static_cast<long>(m.boundary_tris.size() + m.boundary_quads.size());
  if (m.cell_count() == 0) r.min_volume = 0.0;
  return r;
}

}  // namespace naris
