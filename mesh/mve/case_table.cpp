#include "mesh/mve/case_table.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cstring>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <unordered_map>

#include "core/error.h"
#include "mesh/mve/fill_component.h"

namespace naris::mve {

std::uint16_t crossing_edges(std::uint8_t config) {
  std::uint16_t mask = 0;
  for (int e = 0; e < 12; ++e)
    if ((config >> kEdge[e][0] & 1) != (config >> kEdge[e][1] & 1))
      mask |= static_cast<std::uint16_t>(1u << e);
  return mask;
}

std::uint8_t edge_faces(std::uint8_t config) {
  std::uint8_t mask = 0;
  for (int f = 0; f < 6; ++f) {
    const auto& c = kFace[f];
    int inside = 0;
    bool adjacent = false;
    for (int i = 0; i < 4; ++i) {
      inside += config >> c[i] & 1;
      adjacent = adjacent || ((config >> c[i] & 1) && (config >> c[(i + 1) % 4] & 1));
    }
    if (inside == 2 && adjacent) mask |= static_cast<std::uint8_t>(1u << f);
  }
  return mask;
}

std::uint8_t choice_faces(std::uint8_t config) {
  return ambiguous_faces(config) | edge_faces(config);
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
void tessellate_face(std::uint8_t config, std::uint8_t choices, int f, CaseEntry& entry) {
  const auto& c = kFace[f];
  bool in[4];
  int count = 0;
  for (int i = 0; i < 4; ++i) count += in[i] = config >> c[i] & 1;
  auto iso = [&](int i) {  // isopoint on the face edge from c[i] to c[i+1]
    return kEdgePoint0 + kFaceEdge[f][i % 4];
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
      if (m < 4 && (choices >> f & 1)) {  // one inside edge, a whole trapezoid (case_table.h)
        out.push_back(quad(iso(m + 3), v(m), v(m + 1), iso(m + 1)));
      } else if (m < 4) {  // rule 3: one inside edge; three triangles through the face point
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
        if (choices >> f & 1) out.push_back(quad(iso(m), iso(m + 1), iso(m + 2), iso(m + 3)));
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

// Bit f is set when cube point x (a vertex, edge point or face point) lies on face f.
std::uint8_t faces_touching(int x) {
  static const auto masks = [] {
    std::array<std::uint8_t, kPrivatePoint0> m{};
    for (int f = 0; f < 6; ++f) {
      const auto& c = kFace[f];
      auto on = [&](int v) { return std::find(c.begin(), c.end(), v) != c.end(); };
      for (int y = 0; y < kPrivatePoint0; ++y) {
        const bool touches = y < kEdgePoint0 ? on(y)
                             : y < kFacePoint0
                                 ? on(kEdge[y - kEdgePoint0][0]) && on(kEdge[y - kEdgePoint0][1])
                                 : y - kFacePoint0 == f;
        if (touches) m[y] |= static_cast<std::uint8_t>(1u << f);
      }
    }
    return m;
  }();
  return x < kPrivatePoint0 ? masks[x] : 0;
}

// A triangle of cube points that lies on one cube face.
bool on_one_cube_face(const Polygon& t) {
  return (faces_touching(t.p[0]) & faces_touching(t.p[1]) & faces_touching(t.p[2])) != 0;
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
// Ways of fanning a component's isosurface loops tried by the fewest-cell search.
constexpr int kMaxLoopFans = 12;
// Candidates kept per component: single-apex fills (the most robust first), then multi-apex.
constexpr std::size_t kSingleApexKept = 6;
constexpr std::size_t kMultiApexKept = 2;

// Cone from apex x over every boundary polygon of the component that does not contain it.
// Returns false when x lies on a cube face whose polygons are not a fan from x: that face
// would then be split differently from the neighbour's side.
bool cone_from(int x, const std::vector<Polygon>& face_polys, const std::vector<int>& poly_face,
               const std::vector<std::vector<int>>& loops, bool apex_is_centre,
               const std::vector<int>& component_points, int fan, Tessellation& tess) {
  if (x < kPrivatePoint0) {
    for (std::size_t i = 0; i < face_polys.size(); ++i)
      if ((faces_touching(x) >> poly_face[i] & 1) &&
          !(face_polys[i].size == 3 && contains(face_polys[i], x)))
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
  for (const auto& t : tess.iso_triangles)
    if (on_one_cube_face(t)) return false;
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

// The fewest cells that fill a component using its own points only (no private point): an
// advancing front over the component's boundary, where each step puts a tetrahedron on a front
// triangle or a pyramid on a front quadrilateral, with its apex at one of the component's points.
// When the front closes and every cell is positive at every sampled placement, the cells tile the
// component at those placements (their boundary is the component's, and no cell is inverted), so
// no overlap test is needed.
class FewestCells {
 public:
  FewestCells(const std::vector<Points>& samples, const std::vector<int>& points)
      : samples_(samples), points_(points) {}

  // The fill with the fewest cells found for this boundary (outward polygons), or none; the
  // search stops after a fixed number of steps and keeps the best found by then.
  std::vector<CellTemplate> search(const std::vector<Polygon>& boundary) {
    front_.clear();
    for (const auto& f : boundary) front_.push_back(canonical(f));
    cells_.clear();
    best_.clear();
    steps_ = 0;
    dfs();
    return best_;
  }

 private:
  static constexpr long kMaxSteps = 2000;

  struct Move {
    std::size_t base;  // front polygon the cell stands on
    int apex;
    int closed = 0;  // front polygons its cell closes besides its base (closes())
  };

  // An oriented polygon rotated to start at its smallest id: then two polygons are the same
  // oriented polygon exactly when their ids are equal.
  static Polygon canonical(Polygon f) {
    int first = 0;
    for (int i = 1; i < f.size; ++i)
      if (f.p[i] < f.p[first]) first = i;
    std::rotate(f.p.begin(), f.p.begin() + first, f.p.begin() + f.size);
    return f;
  }
  // (A canonical triangle's unused fourth id is 0, which a canonical quadrilateral never has
  // there, so the four ids alone tell them apart.)
  static bool same(const Polygon& a, const Polygon& b) {
    std::uint32_t x, y;
    std::memcpy(&x, a.p.data(), 4);
    std::memcpy(&y, b.p.data(), 4);
    return x == y;
  }
  // The cell on the inner side of front polygon f with apex x (f's normal points away from the
  // unfilled region, as cone_from's bases).
  static CellTemplate cone(const Polygon& f, int x) {
    const auto ux = static_cast<std::uint8_t>(x);
    const auto& p = f.p;
    if (f.size == 3) return {4, {p[0], p[2], p[1], ux, 0}};
    return {5, {p[0], p[3], p[2], p[1], ux}};
  }
  bool positive(const CellTemplate& c) {
    std::uint64_t key = c.size;
    for (int i = 0; i < c.size; ++i) key = key << 6 | c.p[i];
    if (const auto it = memo_.find(key); it != memo_.end()) return it->second;
    Tessellation t;
    t.cells.push_back(c);
    bool ok = true;
    for (const auto& s : samples_) {
      Points x = s;
      if (!(place_and_measure(t, x, false).volume6 > 6e-14)) {
        ok = false;
        break;
      }
    }
    memo_.emplace(key, ok);
    return ok;
  }

  // How many front polygons the move's cell closes besides its base, or −1 when a side face
  // would double a front polygon or lie on a cube face without closing against the boundary
  // there (nothing could close it later).
  int closes(const Move& m) const {
    const Polygon& base = front_[m.base];
    int closed = 0;
    for (int e = 0; e < base.size; ++e) {
      const int a = base.p[e], b = base.p[(e + 1) % base.size];
      const Polygon outward = canonical(tri(b, a, m.apex)), inward = canonical(tri(a, b, m.apex));
      bool found = false;
      for (std::size_t i = 0; i < front_.size() && !found; ++i) {
        if (i == m.base) continue;
        if (same(front_[i], outward))
          found = true;
        else if (same(front_[i], inward))
          return -1;
      }
      if (found)
        ++closed;
      else if (on_one_cube_face(inward))
        return -1;
    }
    return closed;
  }

  // The front after a move that closes().
  void advance(const Move& m, std::vector<Polygon>& next) const {
    const Polygon& base = front_[m.base];
    next.clear();
    for (std::size_t i = 0; i < front_.size(); ++i)
      if (i != m.base) next.push_back(front_[i]);
    for (int e = 0; e < base.size; ++e) {
      const int a = base.p[e], b = base.p[(e + 1) % base.size];
      const Polygon outward = canonical(tri(b, a, m.apex));
      const auto at = std::find_if(next.begin(), next.end(),
                                   [&](const Polygon& f) { return same(f, outward); });
      if (at != next.end())
        next.erase(at);
      else
        next.push_back(canonical(tri(a, b, m.apex)));
    }
  }

  // The cells that can close front polygon i: cones on it, and for a triangle, pyramids on a
  // front quadrilateral that have it as a side.
  // Stops at `limit` moves: the caller only needs to know that there are that many.
  void moves_closing(std::size_t i, std::vector<Move>& moves, std::size_t limit) {
    moves.clear();
    const Polygon& f = front_[i];
    auto consider = [&](Move m) {
      m.closed = closes(m);
      if (m.closed >= 0 && positive(cone(front_[m.base], m.apex))) moves.push_back(m);
      return moves.size() < limit;
    };
    for (int x : points_)
      if (!contains(f, x) && !consider({i, x})) return;
    if (f.size != 3) return;
    for (std::size_t j = 0; j < front_.size(); ++j) {
      const Polygon& q = front_[j];
      if (q.size != 4) continue;
      for (int e = 0; e < 4; ++e) {
        // The side on quad edge a → b is (b, a, apex): the triangle's third point.
        const int a = q.p[e], b = q.p[(e + 1) % 4];
        for (int k = 0; k < 3; ++k)
          if (f.p[k] == b && f.p[(k + 1) % 3] == a && !contains(q, f.p[(k + 2) % 3]) &&
              !consider({j, f.p[(k + 2) % 3]}))
            return;
      }
    }
  }

  void dfs() {
    if (++steps_ > kMaxSteps) return;
    if (front_.empty()) {
      if (best_.empty() || cells_.size() < best_.size()) best_ = cells_;
      return;
    }
    // Each cell removes at most five front polygons (a pyramid closing against all its sides).
    if (!best_.empty() && cells_.size() + (front_.size() + 4) / 5 >= best_.size()) return;
    // The front polygon with the fewest ways to close it first.
    std::vector<Move> moves, fewest;
    for (std::size_t i = 0; i < front_.size(); ++i) {
      moves_closing(i, moves, i == 0 ? points_.size() + front_.size() : fewest.size());
      if (i == 0 || moves.size() < fewest.size()) fewest.swap(moves);
      if (fewest.empty()) return;
      if (fewest.size() == 1) break;  // forced
    }
    // Moves that close the most first: good fills are found early.
    std::vector<std::pair<int, std::size_t>> order;
    for (std::size_t k = 0; k < fewest.size(); ++k) order.push_back({-fewest[k].closed, k});
    std::sort(order.begin(), order.end());
    std::vector<Polygon> next;
    for (const auto& [closed, k] : order) {
      const Move m = fewest[k];
      advance(m, next);
      const CellTemplate cell = cone(front_[m.base], m.apex);
      std::vector<Polygon> saved = std::move(front_);
      front_ = std::move(next);
      cells_.push_back(cell);
      dfs();
      cells_.pop_back();
      front_ = std::move(saved);
      if (steps_ > kMaxSteps) return;
    }
  }

  const std::vector<Points>& samples_;
  const std::vector<int>& points_;
  std::vector<Polygon> front_;
  std::vector<CellTemplate> cells_, best_;
  std::unordered_map<std::uint64_t, bool> memo_;
  long steps_ = 0;
};

// Fills with the fewest cells on the component's own points (FewestCells), one for each way of
// fanning its isosurface loops from one of their points, up to kMaxLoopFans ways.
std::vector<Tessellation> fewest_cell_fills(const std::vector<Points>& samples,
                                            const std::vector<int>& points,
                                            const std::vector<Polygon>& face_polys,
                                            const std::vector<std::vector<int>>& loops) {
  std::vector<Tessellation> fills;
  FewestCells fewest(samples, points);
  std::vector<int> fan(loops.size(), 0);
  for (int combination = 0; combination < kMaxLoopFans; ++combination) {
    Tessellation tess;
    for (std::size_t l = 0; l < loops.size(); ++l) {
      const auto& loop = loops[l];
      const int n = static_cast<int>(loop.size()), s = fan[l];
      for (int i = 1; i + 1 < n; ++i)
        tess.iso_triangles.push_back(tri(loop[s], loop[(s + i) % n], loop[(s + i + 1) % n]));
    }
    // An isosurface triangle flat on a cube face would coincide with the face itself.
    if (std::none_of(tess.iso_triangles.begin(), tess.iso_triangles.end(), on_one_cube_face)) {
      std::vector<Polygon> boundary = face_polys;
      boundary.insert(boundary.end(), tess.iso_triangles.begin(), tess.iso_triangles.end());
      tess.cells = fewest.search(boundary);
      if (!tess.cells.empty()) fills.push_back(std::move(tess));
    }
    // The next combination: an odometer over the loops' distinct fans (a triangle has one, a
    // quadrilateral two: fans from opposite corners share their diagonal).
    auto fans = [](std::size_t n) { return n == 3 ? 1 : n == 4 ? 2 : static_cast<int>(n); };
    std::size_t l = 0;
    while (l < loops.size() && ++fan[l] >= fans(loops[l].size())) fan[l++] = 0;
    if (l == loops.size()) break;
  }
  return fills;
}

CaseEntry build_entry(std::uint8_t config, std::uint8_t face_choices, const Sampler& sampler) {
  CaseEntry entry;
  for (int f = 0; f < 6; ++f) tessellate_face(config, face_choices, f, entry);
  entry.edge_mask = crossing_edges(config);

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

  std::vector<Points> samples(sampler.params.size());
  for (std::size_t s = 0; s < samples.size(); ++s)
    sample_points(entry, sampler.params[s], samples[s]);

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
      for (const Points& sample : samples) {
        Points pts = sample;  // place_and_measure writes the private points
        if (!(place_and_measure(tess, pts, false).volume6 > 6e-14)) ++failures;  // 6× volume
      }
      ranked.push_back({{failures, static_cast<int>(tess.cells.size())}, std::move(tess)});
    }
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    if (ranked.size() > kSingleApexKept) ranked.resize(kSingleApexKept);
    // The multi-apex fills come after: they have fewer cells and nodes, but ranked first they
    // made the drag on a sphere converge worse (docs/results/forces.md), so a cube takes one only
    // where no single-apex fill is well shaped and it is better shaped.
    std::vector<Tessellation> multi = fewest_cell_fills(samples, cpoints, cpolys, cloops);
    std::stable_sort(multi.begin(), multi.end(),
                     [](const auto& a, const auto& b) { return a.cells.size() < b.cells.size(); });
    Component comp;
    for (auto& r : ranked) comp.candidates.push_back(std::move(r.second));
    for (std::size_t i = 0; i < std::min(multi.size(), kMultiApexKept); ++i)
      comp.candidates.push_back(std::move(multi[i]));
    {
      std::array<double, 12> mid;
      mid.fill(0.5);
      Points pts;
      sample_points(entry, mid, pts);
      double best_shape = -INFINITY;
      for (std::size_t r = 0; r < comp.candidates.size(); ++r) {
        Points copy = pts;
        const FillMeasure m = place_and_measure(comp.candidates[r], copy);
        if (!(m.volume6 > 6e-12)) continue;
        if (m.shape > best_shape)
          best_shape = m.shape, comp.midpoint_candidate = static_cast<int>(r);
        if (m.shape >= kGoodShape) break;
      }
    }
    comp.face_polygons = cpolys;
    for (const auto& loop : cloops) comp.loops.emplace_back(loop.begin(), loop.end());
    entry.components.push_back(std::move(comp));
  }
  return entry;
}

// Entries are built on first use: a mesh meets few of them, and each entry's fewest-cell search
// costs far more than looking it up.
struct Table {
  std::vector<CaseEntry> entries = std::vector<CaseEntry>(256 * 64);
  std::vector<std::once_flag> built = std::vector<std::once_flag>(256 * 64);
  const Sampler sampler;
  const CaseEntry& at(std::uint8_t config, std::uint8_t mask) {
    const std::size_t i = static_cast<std::size_t>(config) * 64 + mask;
    std::call_once(built[i], [&] { entries[i] = build_entry(config, mask, sampler); });
    return entries[i];
  }
};

Table& table() {
  static Table t;
  return t;
}

}  // namespace

const CaseEntry& case_entry(std::uint8_t config, std::uint8_t choices) {
  return table().at(config, static_cast<std::uint8_t>(choices & choice_faces(config)));
}

}  // namespace naris::mve
