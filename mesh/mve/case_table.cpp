#include "mesh/mve/case_table.h"

#include <Eigen/Dense>
#include <algorithm>
#include <map>
#include <numeric>
#include <random>

#include "core/error.h"
#include "mesh/mve/fill_component.h"

namespace naris::mve {

int edge_between(int a, int b) {
  for (int e = 0; e < 12; ++e)
    if ((kEdge[e][0] == a && kEdge[e][1] == b) || (kEdge[e][0] == b && kEdge[e][1] == a)) return e;
  return -1;
}

std::uint8_t ambiguous_faces(std::uint8_t config) {
  std::uint8_t mask = 0;
  for (int f = 0; f < 6; ++f) {
    const auto& c = kFace[f];
    const bool i0 = config >> c[0] & 1, i1 = config >> c[1] & 1, i2 = config >> c[2] & 1,
               i3 = config >> c[3] & 1;
    if (i0 == i2 && i1 == i3 && i0 != i1) mask |= static_cast<std::uint8_t>(1u << f);
  }
  return mask;
}

namespace {

Polygon tri(int a, int b, int c) {
  return {3,
          {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b), static_cast<std::uint8_t>(c),
           0}};
}
Polygon quad(int a, int b, int c, int d) {
  return {4,
          {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b), static_cast<std::uint8_t>(c),
           static_cast<std::uint8_t>(d)}};
}
bool contains(const Polygon& poly, int x) {
  for (int i = 0; i < poly.size; ++i)
    if (poly.p[i] == x) return true;
  return false;
}

// The face tessellation rules of 3.2.3 for face f. Every polygon is counter-clockwise seen from
// outside the cube.
void tessellate_face(std::uint8_t config, std::uint8_t connected, int f, CaseEntry& entry) {
  const auto& c = kFace[f];
  bool in[4];
  int count = 0;
  for (int i = 0; i < 4; ++i) count += in[i] = config >> c[i] & 1;
  auto iso = [&](int i) {  // isopoint on the face edge from c[i] to c[i+1]
    return kEdgePoint0 + edge_between(c[i % 4], c[(i + 1) % 4]);
  };
  auto v = [&](int i) { return c[i % 4]; };
  auto& out = entry.face_polygons[f];
  entry.face_point_edges[f] = {-1, -1};
  switch (count) {
    case 4:  // rule 1: the face stays a quadrilateral
      out.push_back(quad(c[0], c[1], c[2], c[3]));
      break;
    case 3: {  // rule 2: three triangles fanned from the vertex opposite the outside one
      int m = 0;
      while (in[m]) ++m;
      const int a = v(m + 2);
      out.push_back(tri(a, v(m + 3), iso(m + 3)));
      out.push_back(tri(a, iso(m + 3), iso(m)));
      out.push_back(tri(a, iso(m), v(m + 1)));
      break;
    }
    case 2: {
      int m = 0;
      while (m < 4 && !(in[m] && in[(m + 1) % 4])) ++m;
      if (m < 4) {  // rule 3: one inside edge; three triangles through the face point
        const int fp = kFacePoint0 + f;
        out.push_back(tri(fp, iso(m + 3), v(m)));
        out.push_back(tri(fp, v(m), v(m + 1)));
        out.push_back(tri(fp, v(m + 1), iso(m + 1)));
        entry.face_point_edges[f] = {static_cast<std::int8_t>(iso(m + 1) - kEdgePoint0),
                                     static_cast<std::int8_t>(iso(m + 3) - kEdgePoint0)};
        entry.face_point_mask |= static_cast<std::uint8_t>(1u << f);
      } else {  // rule 4: diagonal; the saddle decides whether a quadrilateral joins them
        m = in[0] ? 0 : 1;
        out.push_back(tri(v(m), iso(m), iso(m + 3)));
        out.push_back(tri(v(m + 2), iso(m + 2), iso(m + 1)));
        if (connected >> f & 1) out.push_back(quad(iso(m), iso(m + 1), iso(m + 2), iso(m + 3)));
      }
      break;
    }
    case 1: {  // rule 5
      int m = 0;
      while (!in[m]) ++m;
      out.push_back(tri(v(m), iso(m), iso(m + 3)));
      break;
    }
    default:
      break;
  }
}

struct UnionFind {
  std::array<int, kPrivatePoint0> parent;
  UnionFind() { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) { return parent[x] == x ? x : parent[x] = find(parent[x]); }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

std::vector<int> faces_touching(int x) {
  std::vector<int> faces;
  for (int f = 0; f < 6; ++f) {
    const auto& c = kFace[f];
    const bool on = [&] {
      if (x < kEdgePoint0) return std::find(c.begin(), c.end(), x) != c.end();
      if (x < kFacePoint0) {
        const auto& e = kEdge[x - kEdgePoint0];
        return std::find(c.begin(), c.end(), e[0]) != c.end() &&
               std::find(c.begin(), c.end(), e[1]) != c.end();
      }
      return x - kFacePoint0 == f;
    }();
    if (on) faces.push_back(f);
  }
  return faces;
}

// Random placements of the isopoints, including extreme ones, used to decide which
// tessellations are valid whatever the data.
struct Sampler {
  std::vector<std::array<double, 12>> params;
  Sampler() {
    std::mt19937 rng(20261122);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double lo = 1e-3, hi = 1.0 - 1e-3;
    for (int s = 0; s < 48; ++s) {
      std::array<double, 12> t;
      for (double& x : t) {
        if (s < 16)
          x = lo + (hi - lo) * u(rng);
        else if (s < 32)
          x = u(rng) < 0.5 ? lo : hi;
        else
          x = std::array<double, 3>{lo, 0.5, hi}[static_cast<int>(u(rng) * 3) % 3];
      }
      params.push_back(t);
    }
  }
};

using Points = std::array<Eigen::Vector3d, kMaxLocalPoints>;

void sample_points(const CaseEntry& entry, const std::array<double, 12>& t, Points& x) {
  for (int v = 0; v < 8; ++v) x[v] = Eigen::Vector3d(kCorner[v][0], kCorner[v][1], kCorner[v][2]);
  for (int e = 0; e < 12; ++e)
    x[kEdgePoint0 + e] = x[kEdge[e][0]] + t[e] * (x[kEdge[e][1]] - x[kEdge[e][0]]);
  for (int f = 0; f < 6; ++f) {
    const auto& fe = entry.face_point_edges[f];
    if (fe[0] >= 0) x[kFacePoint0 + f] = 0.5 * (x[kEdgePoint0 + fe[0]] + x[kEdgePoint0 + fe[1]]);
  }
}

constexpr int kFanFromApex = -2;

// Cone from apex x over every boundary polygon of the component that does not contain it.
// Returns false when x lies on a cube face whose polygons are not a fan from x: that face
// would then be split differently from the neighbour's side.
bool cone_from(int x, const std::vector<Polygon>& face_polys, const std::vector<int>& poly_face,
               const std::vector<std::vector<int>>& loops, bool apex_is_centre,
               const std::vector<int>& component_points, int fan, Tessellation& tess) {
  if (x < kPrivatePoint0) {
    for (int f : faces_touching(x))
      for (std::size_t i = 0; i < face_polys.size(); ++i)
        if (poly_face[i] == f && !(face_polys[i].size == 3 && contains(face_polys[i], x)))
          return false;
  }
  int next_private = kPrivatePoint0;
  if (apex_is_centre) {
    tess.privates.push_back({{component_points.begin(), component_points.end()}});
    x = next_private++;
  }
  for (const auto& loop : loops) {
    const int n = static_cast<int>(loop.size());
    if (fan == kFanFromApex) {
      // The apex sits on the isosurface: the loop is fanned from it and no cell rests on it.
      for (int i = 0; i < n; ++i) tess.iso_triangles.push_back(tri(x, loop[i], loop[(i + 1) % n]));
      continue;
    }
    const auto at = std::find(loop.begin(), loop.end(), x);
    if (at != loop.end()) {
      const int s = static_cast<int>(at - loop.begin());
      for (int i = 1; i + 1 < n; ++i)
        tess.iso_triangles.push_back(tri(x, loop[(s + i) % n], loop[(s + i + 1) % n]));
    } else if (n == 3) {
      tess.iso_triangles.push_back(tri(loop[0], loop[1], loop[2]));
    } else if (fan >= 0) {
      const int s = fan % n;
      for (int i = 1; i + 1 < n; ++i)
        tess.iso_triangles.push_back(tri(loop[s], loop[(s + i) % n], loop[(s + i + 1) % n]));
    } else {
      PrivatePoint centre;
      for (int p : loop) centre.mean_of.push_back(static_cast<std::uint8_t>(p));
      tess.privates.push_back(centre);
      const int g = next_private++;
      for (int i = 0; i < n; ++i) tess.iso_triangles.push_back(tri(g, loop[i], loop[(i + 1) % n]));
    }
  }
  // An isosurface triangle lying flat on a cube face would coincide with the face itself.
  for (const auto& t : tess.iso_triangles) {
    if (t.p[0] >= kPrivatePoint0 || t.p[1] >= kPrivatePoint0 || t.p[2] >= kPrivatePoint0) continue;
    for (int f : faces_touching(t.p[0])) {
      const auto fb = faces_touching(t.p[1]), fc = faces_touching(t.p[2]);
      if (std::find(fb.begin(), fb.end(), f) != fb.end() &&
          std::find(fc.begin(), fc.end(), f) != fc.end())
        return false;
    }
  }
  auto add_cone = [&](const Polygon& poly) {
    if (contains(poly, x)) return;
    CellTemplate cell;
    const auto& p = poly.p;
    const auto ux = static_cast<std::uint8_t>(x);
    if (poly.size == 3)
      cell = {4, {p[0], p[2], p[1], ux, 0}};
    else
      cell = {5, {p[0], p[3], p[2], p[1], ux}};
    tess.cells.push_back(cell);
  };
  for (const auto& poly : face_polys) add_cone(poly);
  for (const auto& poly : tess.iso_triangles) add_cone(poly);
  return true;
}

CaseEntry build_entry(std::uint8_t config, std::uint8_t connected, const Sampler& sampler) {
  CaseEntry entry;
  for (int f = 0; f < 6; ++f) tessellate_face(config, connected, f, entry);
  for (int e = 0; e < 12; ++e)
    if ((config >> kEdge[e][0] & 1) != (config >> kEdge[e][1] & 1))
      entry.edge_mask |= static_cast<std::uint16_t>(1u << e);

  // Components: points joined by a common face polygon belong together.
  UnionFind uf;
  std::vector<Polygon> polys;
  std::vector<int> poly_face;
  for (int f = 0; f < 6; ++f)
    for (const auto& p : entry.face_polygons[f]) {
      polys.push_back(p);
      poly_face.push_back(f);
      for (int i = 1; i < p.size; ++i) uf.unite(p.p[0], p.p[i]);
    }
  if (polys.empty()) return entry;

  // The cut segments are the polygon edges not matched by an opposite edge (on the same face or
  // across a cube edge); reversed, they chain into the isosurface loops.
  std::map<std::pair<int, int>, int> half_edges;
  for (const auto& p : polys)
    for (int i = 0; i < p.size; ++i) ++half_edges[{p.p[i], p.p[(i + 1) % p.size]}];
  std::map<int, int> next;
  for (const auto& [e, n] : half_edges) {
    if (n != 1) fail("MVE table: edge used twice in configuration {}", config);
    if (!half_edges.count({e.second, e.first})) next[e.second] = e.first;
  }
  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    std::vector<int> loop;
    int at = next.begin()->first;
    while (next.count(at)) {
      loop.push_back(at);
      const int to = next[at];
      next.erase(at);
      at = to;
    }
    loops.push_back(loop);
  }

  std::map<int, int> root_to_component;
  for (const auto& p : polys) root_to_component.emplace(uf.find(p.p[0]), 0);
  int nc = 0;
  for (auto& [root, id] : root_to_component) id = nc++;

  for (int c = 0; c < nc; ++c) {
    std::vector<Polygon> cpolys;
    std::vector<int> cface;
    std::vector<int> cpoints;
    for (std::size_t i = 0; i < polys.size(); ++i) {
      if (root_to_component[uf.find(polys[i].p[0])] != c) continue;
      cpolys.push_back(polys[i]);
      cface.push_back(poly_face[i]);
      for (int k = 0; k < polys[i].size; ++k) cpoints.push_back(polys[i].p[k]);
    }
    std::sort(cpoints.begin(), cpoints.end());
    cpoints.erase(std::unique(cpoints.begin(), cpoints.end()), cpoints.end());
    std::vector<std::vector<int>> cloops;
    for (const auto& loop : loops)
      if (root_to_component[uf.find(loop[0])] == c) cloops.push_back(loop);

    // Candidate apexes: every point of the component on the cube, then a centre point O.
    std::vector<std::pair<std::pair<int, int>, Tessellation>> ranked;  // ((failures, cells), t)
    // Two placements of O: the mean of all the component's points, and the mean of its inside
    // vertices alone (deeper inside when the cut is a small corner).
    std::vector<int> inside_vertices;
    for (int p : cpoints)
      if (p < kEdgePoint0) inside_vertices.push_back(p);
    std::vector<int> apexes = cpoints;
    apexes.push_back(-1);
    if (inside_vertices.size() >= 2) apexes.push_back(-2);
    // Loops not through the apex are fanned from their centre (fan = -1) or from one of their
    // own points (fan = 0, 1, ...): different triangulations suit different saddles.
    std::size_t longest_loop = 0;
    for (const auto& loop : cloops) longest_loop = std::max(longest_loop, loop.size());
    std::vector<std::pair<int, int>> choices;
    for (int x : apexes)
      for (int fan = -1; fan < static_cast<int>(longest_loop); ++fan) choices.push_back({x, fan});
    // A single loop can be fanned from its own centroid G, which then serves as the apex: G is
    // strictly inside the cube and every remaining polygon lies on a cube face, so every cone
    // has positive volume whatever the isopoints do. This candidate always exists.
    if (cloops.size() == 1) choices.push_back({-3, kFanFromApex});
    for (auto [x, fan] : choices) {
      Tessellation tess;
      const bool centre = x < 0;
      const std::vector<int>& centre_of =
          x == -2 ? inside_vertices : (x == -3 ? cloops.front() : cpoints);
      if (!cone_from(centre ? kPrivatePoint0 : x, cpolys, cface, cloops, centre, centre_of, fan,
                     tess))
        continue;
      int failures = 0;
      Points pts;
      for (const auto& t : sampler.params) {
        sample_points(entry, t, pts);
        if (!(place_and_measure(tess, pts, false).volume6 > 6e-14)) ++failures;  // 6× volume
      }
      ranked.push_back({{failures, static_cast<int>(tess.cells.size())}, std::move(tess)});
    }
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    Component comp;
    {
      std::array<double, 12> mid;
      mid.fill(0.5);
      Points pts;
      sample_points(entry, mid, pts);
      double best_shape = -INFINITY;
      for (std::size_t r = 0; r < std::min<std::size_t>(ranked.size(), 6); ++r) {
        Points copy = pts;
        const FillMeasure m = place_and_measure(ranked[r].second, copy);
        if (!(m.volume6 > 6e-12)) continue;
        if (m.shape > best_shape)
          best_shape = m.shape, comp.midpoint_candidate = static_cast<int>(r);
      }
    }
    comp.face_polygons = cpolys;
    for (const auto& loop : cloops) comp.loops.emplace_back(loop.begin(), loop.end());
    for (auto& r : ranked) {
      if (comp.candidates.size() >= 6) break;
      comp.candidates.push_back(std::move(r.second));
    }
    entry.components.push_back(std::move(comp));
  }
  return entry;
}

struct Table {
  std::vector<CaseEntry> entries;  // 256 × 64, only masks ⊆ ambiguous faces filled
  std::size_t distinct = 0;
  Table() : entries(256 * 64) {
    const Sampler sampler;
    for (int config = 0; config < 256; ++config) {
      const auto amb = ambiguous_faces(static_cast<std::uint8_t>(config));
      for (int mask = 0; mask < 64; ++mask) {
        if ((mask & ~amb) != 0) continue;
        entries[static_cast<std::size_t>(config * 64 + mask)] = build_entry(
            static_cast<std::uint8_t>(config), static_cast<std::uint8_t>(mask), sampler);
        ++distinct;
      }
    }
  }
};

const Table& table() {
  static const Table t;
  return t;
}

}  // namespace

const CaseEntry& case_entry(std::uint8_t config, std::uint8_t connected) {
  const auto mask = static_cast<std::uint8_t>(connected & ambiguous_faces(config));
  return table().entries[static_cast<std::size_t>(config) * 64 + mask];
}

std::size_t case_entry_count() {
  return table().distinct;
}

}  // namespace naris::mve
