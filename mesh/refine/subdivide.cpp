#include "mesh/refine/subdivide.h"

#include <algorithm>
#include <cstdint>
#include <limits>

#include "core/error.h"

namespace naris {

namespace {

using QuadKey = std::array<NodeId, 4>;
QuadKey quad_key(NodeId a, NodeId b, NodeId c, NodeId d) {
  QuadKey k = {a, b, c, d};
  std::sort(k.begin(), k.end());
  return k;
}

// Where the new nodes go: every edge's midpoint, every quadrilateral's centre (hexahedron
// faces, pyramid bases) and every hexahedron's centre, numbered just after the lowest input node
// each derives from.
class NewNodes {
 public:
  explicit NewNodes(const HybridMesh& m) : mesh_(m) {
    edges_.reserve(6 * m.tets.size() + 8 * m.pyramids.size() + 12 * m.hexes.size());
    auto add_edges = [&](const auto& cells, const auto& table) {
      for (const auto& c : cells)
        for (const auto& e : table) edges_.push_back(edge_key(c[e[0]], c[e[1]]));
    };
    add_edges(m.tets, kTetEdges);
    add_edges(m.pyramids, kPyramidEdges);
    add_edges(m.hexes, kHexEdges);
    unique_sort(edges_);
    quads_.reserve(m.pyramids.size() + 6 * m.hexes.size());
    for (const auto& p : m.pyramids) quads_.push_back(quad_key(p[0], p[1], p[2], p[3]));
    for (const auto& h : m.hexes)
      for (const auto& f : kHexFaces)
        quads_.push_back(quad_key(h[f.v[0]], h[f.v[1]], h[f.v[2]], h[f.v[3]]));
    unique_sort(quads_);
    const std::size_t total = m.nodes.size() + edges_.size() + quads_.size() + m.hexes.size();
    if (total > static_cast<std::size_t>(std::numeric_limits<NodeId>::max()))
      fail("subdivide: the refined mesh would have {} nodes, more than node ids can number", total);
    number_nodes();
  }

  NodeId node(NodeId n) const { return original_[n]; }
  NodeId edge(NodeId a, NodeId b) const { return edge_id_[find(edges_, edge_key(a, b))]; }
  NodeId quad(NodeId a, NodeId b, NodeId c, NodeId d) const {
    return quad_id_[find(quads_, quad_key(a, b, c, d))];
  }
  NodeId hex(std::size_t h) const { return hex_id_[h]; }

  Prolongation prolongation() const {
    const std::size_t total = original_.size() + edge_id_.size() + quad_id_.size() + hex_id_.size();
    Prolongation p;
    p.offsets.assign(total + 1, 0);
    for (NodeId id : original_) p.offsets[static_cast<std::size_t>(id) + 1] = 1;
    for (NodeId id : edge_id_) p.offsets[static_cast<std::size_t>(id) + 1] = 2;
    for (NodeId id : quad_id_) p.offsets[static_cast<std::size_t>(id) + 1] = 4;
    for (NodeId id : hex_id_) p.offsets[static_cast<std::size_t>(id) + 1] = 8;
    for (std::size_t i = 0; i < total; ++i) p.offsets[i + 1] += p.offsets[i];
    p.parents.resize(static_cast<std::size_t>(p.offsets[total]));
    auto put = [&](NodeId id, auto... nodes) {
      std::int64_t k = p.offsets[static_cast<std::size_t>(id)];
      ((p.parents[static_cast<std::size_t>(k++)] = nodes), ...);
    };
    for (std::size_t i = 0; i < original_.size(); ++i) put(original_[i], static_cast<NodeId>(i));
    for (std::size_t e = 0; e < edges_.size(); ++e)
      put(edge_id_[e], low(edges_[e]), high(edges_[e]));
    for (std::size_t q = 0; q < quads_.size(); ++q)
      put(quad_id_[q], quads_[q][0], quads_[q][1], quads_[q][2], quads_[q][3]);
    for (std::size_t h = 0; h < hex_id_.size(); ++h) {
      const auto& c = mesh_.hexes[h];
      put(hex_id_[h], c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]);
    }
    return p;
  }

 private:
  template <class T>
  static void unique_sort(std::vector<T>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  // Every face and edge a cell or boundary face names is in the tables unless the mesh is not
  // conforming (a boundary quadrilateral that is no cell's face, say).
  template <class T>
  static std::size_t find(const std::vector<T>& sorted, const T& key) {
    const auto it = std::lower_bound(sorted.begin(), sorted.end(), key);
    if (it == sorted.end() || *it != key)
      fail("subdivide: the mesh is not conforming (a boundary face is not a face of any cell)");
    return static_cast<std::size_t>(it - sorted.begin());
  }
  static NodeId low(std::uint64_t key) { return static_cast<NodeId>(key >> 32); }
  static NodeId high(std::uint64_t key) { return static_cast<NodeId>(key & 0xffffffffu); }

  // Bucket placement: input node k keeps its rank among the input nodes and is followed by the
  // new nodes whose lowest parent is k (edges, then quadrilaterals, then hexahedron centres).
  void number_nodes() {
    const std::size_t n = mesh_.nodes.size();
    std::vector<NodeId> hex_parent(mesh_.hexes.size());
    for (std::size_t h = 0; h < mesh_.hexes.size(); ++h)
      hex_parent[h] = *std::min_element(mesh_.hexes[h].begin(), mesh_.hexes[h].end());
    std::vector<NodeId> followers(n, 0);
    for (auto e : edges_) ++followers[low(e)];
    for (const auto& q : quads_) ++followers[q[0]];
    for (NodeId p : hex_parent) ++followers[p];
    original_.resize(n);
    std::vector<NodeId> next(n);
    NodeId id = 0;
    for (std::size_t k = 0; k < n; ++k) {
      original_[k] = id;
      next[k] = id + 1;
      id += 1 + followers[k];
    }
    edge_id_.resize(edges_.size());
    for (std::size_t e = 0; e < edges_.size(); ++e) edge_id_[e] = next[low(edges_[e])]++;
    quad_id_.resize(quads_.size());
    for (std::size_t q = 0; q < quads_.size(); ++q) quad_id_[q] = next[quads_[q][0]]++;
    hex_id_.resize(mesh_.hexes.size());
    for (std::size_t h = 0; h < hex_parent.size(); ++h) hex_id_[h] = next[hex_parent[h]]++;
  }

  const HybridMesh& mesh_;
  std::vector<std::uint64_t> edges_;
  std::vector<QuadKey> quads_;
  std::vector<NodeId> original_, edge_id_, quad_id_, hex_id_;
};

// Appends a tetrahedron, ordered for a positive volume (the octahedron's and the pyramid's
// inner tetrahedra are listed without regard to orientation).
void add_tet(HybridMesh& out, std::array<NodeId, 4> t) {
  const auto& x = out.nodes;
  if (tet_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) < 0.0) std::swap(t[2], t[3]);
  out.tets.push_back(t);
}

void split_tet(const std::array<NodeId, 4>& t, const NewNodes& nn, HybridMesh& out) {
  const NodeId v[4] = {nn.node(t[0]), nn.node(t[1]), nn.node(t[2]), nn.node(t[3])};
  auto m = [&](int a, int b) { return nn.edge(t[a], t[b]); };
  // The four corner tetrahedra are the parent shrunk towards each vertex: same orientation.
  out.tets.push_back({v[0], m(0, 1), m(0, 2), m(0, 3)});
  out.tets.push_back({m(0, 1), v[1], m(1, 2), m(1, 3)});
  out.tets.push_back({m(0, 2), m(1, 2), v[2], m(2, 3)});
  out.tets.push_back({m(0, 3), m(1, 3), m(2, 3), v[3]});
  // The inner octahedron is cut along its shortest diagonal (the best-shaped of the three
  // splits); its other four vertices form the cycle around that diagonal.
  const std::array<std::array<NodeId, 2>, 3> diagonals = {
      {{m(0, 1), m(2, 3)}, {m(0, 2), m(1, 3)}, {m(0, 3), m(1, 2)}}};
  const std::array<std::array<NodeId, 4>, 3> cycles = {{{m(0, 2), m(1, 2), m(1, 3), m(0, 3)},
                                                        {m(0, 1), m(1, 2), m(2, 3), m(0, 3)},
                                                        {m(0, 1), m(1, 3), m(2, 3), m(0, 2)}}};
  int best = 0;
  double shortest = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d) {
    const double length = (out.nodes[diagonals[d][0]] - out.nodes[diagonals[d][1]]).squaredNorm();
    if (length < shortest) shortest = length, best = d;
  }
  const auto& [a, b] = diagonals[best];
  const auto& c = cycles[best];
  for (int i = 0; i < 4; ++i) add_tet(out, {a, b, c[i], c[(i + 1) % 4]});
}

void split_pyramid(const std::array<NodeId, 5>& p, const NewNodes& nn, HybridMesh& out) {
  NodeId v[5], base[4], side[4];
  for (int i = 0; i < 5; ++i) v[i] = nn.node(p[i]);
  for (int i = 0; i < 4; ++i) {
    base[i] = nn.edge(p[i], p[(i + 1) % 4]);  // midpoint of base edge i → i+1
    side[i] = nn.edge(p[i], p[4]);            // midpoint of lateral edge i → apex
  }
  const NodeId c = nn.quad(p[0], p[1], p[2], p[3]);
  // A pyramid on each base quarter, its apex halfway up the lateral edge above its corner.
  for (int i = 0; i < 4; ++i)
    out.pyramids.push_back({v[i], base[i], c, base[(i + 3) % 4], side[i]});
  // The top pyramid, and the inverted one below its base with its apex at the base centre.
  out.pyramids.push_back({side[0], side[1], side[2], side[3], v[4]});
  out.pyramids.push_back({side[0], side[3], side[2], side[1], c});
  // A tetrahedron under each lateral face, between the two corner pyramids of its base edge.
  for (int i = 0; i < 4; ++i) add_tet(out, {base[i], c, side[i], side[(i + 1) % 4]});
}

void split_hex(const std::array<NodeId, 8>& h, std::size_t index, const NewNodes& nn,
               HybridMesh& out) {
  // The 3×3×3 lattice of the refined hexahedron in its reference coordinates: corners at even
  // positions, edge midpoints where one coordinate is 1, face centres where two are, the centre.
  static constexpr int kCorner[2][2][2] = {{{0, 4}, {3, 7}}, {{1, 5}, {2, 6}}};  // [i][j][k]
  NodeId lattice[3][3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c) {
        NodeId corners[8];
        int count = 0;
        for (int i = 0; i < 2; ++i)
          for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k)
              if ((a == 1 || a == 2 * i) && (b == 1 || b == 2 * j) && (c == 1 || c == 2 * k))
                corners[count++] = h[kCorner[i][j][k]];
        NodeId id;
        if (count == 1)
          id = nn.node(corners[0]);
        else if (count == 2)
          id = nn.edge(corners[0], corners[1]);
        else if (count == 4)
          id = nn.quad(corners[0], corners[1], corners[2], corners[3]);
        else
          id = nn.hex(index);
        lattice[a][b][c] = id;
      }
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z)
        out.hexes.push_back({lattice[x][y][z], lattice[x + 1][y][z], lattice[x + 1][y + 1][z],
                             lattice[x][y + 1][z], lattice[x][y][z + 1], lattice[x + 1][y][z + 1],
                             lattice[x + 1][y + 1][z + 1], lattice[x][y + 1][z + 1]});
}

}  // namespace

HybridMesh subdivide(const HybridMesh& mesh, Prolongation* prolongation) {
  const NewNodes nn(mesh);
  Prolongation means = nn.prolongation();
  HybridMesh out;
  out.patch_names = mesh.patch_names;
  const std::vector<Eigen::Vector3d> x = means.apply(mesh.nodes);
  out.nodes.assign(x.begin(), x.end());
  if (prolongation) *prolongation = std::move(means);
  out.tets.reserve(8 * mesh.tets.size() + 4 * mesh.pyramids.size());
  out.pyramids.reserve(6 * mesh.pyramids.size());
  out.hexes.reserve(8 * mesh.hexes.size());
  for (const auto& t : mesh.tets) split_tet(t, nn, out);
  for (const auto& p : mesh.pyramids) split_pyramid(p, nn, out);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) split_hex(mesh.hexes[h], h, nn, out);

  out.boundary_tris.reserve(4 * mesh.boundary_tris.size());
  out.boundary_tri_patch.reserve(4 * mesh.boundary_tris.size());
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f) {
    const auto& t = mesh.boundary_tris[f];
    const NodeId a = nn.node(t[0]), b = nn.node(t[1]), c = nn.node(t[2]);
    const NodeId ab = nn.edge(t[0], t[1]), bc = nn.edge(t[1], t[2]), ca = nn.edge(t[2], t[0]);
    for (const auto& tri : {std::array<NodeId, 3>{a, ab, ca}, std::array<NodeId, 3>{ab, b, bc},
                            std::array<NodeId, 3>{ca, bc, c}, std::array<NodeId, 3>{ab, bc, ca}}) {
      out.boundary_tris.push_back(tri);
      out.boundary_tri_patch.push_back(mesh.boundary_tri_patch[f]);
    }
  }
  out.boundary_quads.reserve(4 * mesh.boundary_quads.size());
  out.boundary_quad_patch.reserve(4 * mesh.boundary_quads.size());
  for (std::size_t f = 0; f < mesh.boundary_quads.size(); ++f) {
    const auto& q = mesh.boundary_quads[f];
    NodeId v[4], mid[4];
    for (int i = 0; i < 4; ++i) {
      v[i] = nn.node(q[i]);
      mid[i] = nn.edge(q[i], q[(i + 1) % 4]);
    }
    const NodeId c = nn.quad(q[0], q[1], q[2], q[3]);
    for (int i = 0; i < 4; ++i) {
      out.boundary_quads.push_back({v[i], mid[i], c, mid[(i + 3) % 4]});
      out.boundary_quad_patch.push_back(mesh.boundary_quad_patch[f]);
    }
  }
  return out;
}

}  // namespace naris
