#include "mesh/quality/relocate.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <span>
#include <unordered_map>
#include <unordered_set>

#include "core/log.h"
#include "mesh/quality/node_incidence.h"

namespace naris {
namespace {

using Vec = Eigen::Vector3d;
constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;

// surface: slides on the wall's level zero; plane: moves in its flat patch (a cut plane, a box
// side); rim: on the line where the wall meets a flat patch (in the plane, on the level zero).
// along: a rim node where the wall's field is flat (no level zero or gradient to follow) moves
// along the rim itself, towards either of its two neighbours on it.
enum class Freedom : std::uint8_t { fixed, interior, surface, plane, rim, along };

struct Plane {
  Vec normal = Vec::Zero();  // unit
  double offset = 0.0;       // normal·x on the plane
  double tolerance = 0.0;    // of a node on it
  bool holds(const Vec& x) const { return std::abs(normal.dot(x) - offset) <= tolerance; }
  // p moved along the normal to the plane through `on` (exactly `on`'s coordinate for an axis).
  Vec through(const Vec& p, const Vec& on) const {
    Vec q = p - normal.dot(p - on) * normal;
    for (int k = 0; k < 3; ++k)
      if (std::abs(normal[k]) == 1.0) q[k] = on[k];
    return q;
  }
};

// The cells of the mesh in its order (tetrahedra, pyramids, hexahedra) as node spans.
struct Cells {
  const HybridMesh& mesh;
  std::size_t count() const { return mesh.cell_count(); }
  std::span<const NodeId> operator[](std::size_t c) const {
    if (c < mesh.tets.size()) return mesh.tets[c];
    c -= mesh.tets.size();
    if (c < mesh.pyramids.size()) return mesh.pyramids[c];
    return mesh.hexes[c - mesh.pyramids.size()];
  }
};

// A cell's score: the smallest of its metrics over their targets (1 meets every target), or
// −1 when it is inverted or flat. `at` gives node positions.
class Scorer {
 public:
  explicit Scorer(const RelocateOptions& o)
      : dihedral_(o.min_dihedral), jacobian_(o.min_scaled_jacobian), ratio_(o.max_edge_ratio) {}

  template <class At>
  double operator()(std::span<const NodeId> v, const At& at) const {
    std::array<Vec, 8> x;
    for (std::size_t k = 0; k < v.size(); ++k) x[k] = at(v[k]);
    return v.size() == 4 ? tet(x) : v.size() == 5 ? pyramid(x) : hex(x);
  }

 private:
  double tet(const std::array<Vec, 8>& x) const {
    if (!(tet_volume(x[0], x[1], x[2], x[3]) > 0.0)) return -1.0;
    std::array<Vec, 4> n;
    for (int f = 0; f < 4; ++f) {
      const auto& v = kTetFaces[f].v;
      n[f] = (x[v[1]] - x[v[0]]).cross(x[v[2]] - x[v[0]]).normalized();
    }
    // Every two faces of a tetrahedron meet at an edge; the dihedral angle is π minus the angle
    // between their outward normals.
    double cos_max = -1.0;
    for (int f = 0; f < 4; ++f)
      for (int g = f + 1; g < 4; ++g) cos_max = std::max(cos_max, -n[f].dot(n[g]));
    const double dihedral = std::acos(std::clamp(cos_max, -1.0, 1.0)) * kDegreesPerRadian;
    return std::min({dihedral / dihedral_, jacobian(x, kTetCorners) / jacobian_,
                     ratio_ / edge_ratio(x, kTetEdges)});
  }
  double pyramid(const std::array<Vec, 8>& x) const {
    // Both diagonal splits of the base must be positive.
    if (!(std::min({tet_volume(x[0], x[1], x[2], x[4]), tet_volume(x[0], x[2], x[3], x[4]),
                    tet_volume(x[0], x[1], x[3], x[4]), tet_volume(x[1], x[2], x[3], x[4])}) > 0.0))
      return -1.0;
    return std::min(jacobian(x, kPyramidCorners) / jacobian_,
                    ratio_ / edge_ratio(x, kPyramidEdges));
  }
  double hex(const std::array<Vec, 8>& x) const {
    const double j = jacobian(x, kHexCorners) / std::numbers::sqrt2;
    if (!(j > 0.0)) return -1.0;
    return std::min(j / jacobian_, ratio_ / edge_ratio(x, kHexEdges));
  }
  // The smallest corner Jacobian over the edge lengths, scaled to 1 for the regular cell (the
  // quality report's scaled Jacobian).
  template <std::size_t N>
  static double jacobian(const std::array<Vec, 8>& x,
                         const std::array<std::array<int, 4>, N>& corners) {
    double j = INFINITY;
    for (const auto& c : corners) {
      const Vec a = x[c[1]] - x[c[0]], b = x[c[2]] - x[c[0]], e = x[c[3]] - x[c[0]];
      const double norms = a.norm() * b.norm() * e.norm();
      j = std::min(j, norms > 0.0 ? a.cross(b).dot(e) / norms : 0.0);
    }
    return j * std::numbers::sqrt2;
  }
  template <std::size_t E>
  static double edge_ratio(const std::array<Vec, 8>& x,
                           const std::array<std::array<int, 2>, E>& edges) {
    double lo = INFINITY, hi = 0.0;
    for (const auto& e : edges) {
      const double l = (x[e[0]] - x[e[1]]).squaredNorm();
      lo = std::min(lo, l);
      hi = std::max(hi, l);
    }
    return lo > 0.0 ? std::sqrt(hi / lo) : INFINITY;
  }

  double dihedral_, jacobian_, ratio_;
};

// Moves p onto the level zero by Newton steps along the gradient, or with `plane` along the
// gradient's part in it, p kept on the plane through `on`; false when it leaves the function's
// domain, does not settle, or ends farther than `reach` from where it started.
bool project(const LevelSet& wall, Vec& p, double reach, const Plane* plane = nullptr,
             const Vec& on = Vec::Zero()) {
  const Vec start = p;
  for (int it = 0; it < 12; ++it) {
    double value;
    Vec gradient;
    if (!wall.evaluate(p, value, gradient)) return false;
    if (plane) gradient -= gradient.dot(plane->normal) * plane->normal;
    const double g2 = gradient.squaredNorm();
    if (!(g2 > 0.0)) return false;
    const Vec step = value / g2 * gradient;
    p -= step;
    if (plane) p = plane->through(p, on);
    if (step.norm() <= 1e-10 * reach) return (p - start).norm() <= reach;
  }
  return false;
}

// The plane of each patch on which at least 90 % of its nodes lie (to 1e-9 of the mesh's size);
// others get a zero normal. A cut plane's isopoints lie on it, but the collapses of 3.3 may merge
// a rim node into a lattice vertex on the wall, off it. The plane is the one most nodes lie on;
// the nodes off it stay.
std::vector<Plane> flat_patches(const HybridMesh& mesh) {
  const std::size_t n_patches = mesh.patch_names.size();
  std::vector<Vec> area(n_patches, Vec::Zero());
  std::vector<std::vector<NodeId>> nodes(n_patches);
  for_each_boundary_face(mesh, [&](std::span<const NodeId> f, std::int32_t p) {
    area[p] += polygon_vector_area(mesh, f);
    nodes[p].insert(nodes[p].end(), f.begin(), f.end());
  });
  Eigen::AlignedBox3d box;
  for (const auto& x : mesh.nodes) box.extend(x);
  const double tolerance = 1e-9 * box.diagonal().norm();
  std::vector<Plane> planes(n_patches);
  for (std::size_t p = 0; p < n_patches; ++p) {
    auto& on = nodes[p];
    std::sort(on.begin(), on.end());
    on.erase(std::unique(on.begin(), on.end()), on.end());
    if (on.size() < 3 || !(area[p].norm() > 0.0)) continue;
    // The plane through three of its nodes that most nodes lie on (trials with a fixed seed:
    // with nine tenths of the nodes on it, a trial finds it with odds of 0.73), refitted by least
    // squares to the nodes on it.
    Eigen::AlignedBox3d extent;
    for (NodeId n : on) extent.extend(mesh.nodes[n]);
    const double size = extent.diagonal().norm();
    std::mt19937 random(20261207);
    std::uniform_int_distribution<std::size_t> pick(0, on.size() - 1);
    auto count_on = [&](const Plane& plane) {
      std::size_t count = 0;
      for (NodeId n : on) count += plane.holds(mesh.nodes[n]);
      return count;
    };
    Plane best;
    std::size_t most = 0;
    for (int trial = 0; trial < 32; ++trial) {
      const Vec& a = mesh.nodes[on[pick(random)]];
      const Vec cross = (mesh.nodes[on[pick(random)]] - a).cross(mesh.nodes[on[pick(random)]] - a);
      if (!(cross.norm() > 1e-3 * size * size)) continue;  // too close to a line
      const Plane candidate{cross.normalized(), cross.normalized().dot(a), tolerance};
      const std::size_t count = count_on(candidate);
      if (count > most) most = count, best = candidate;
    }
    if (10 * most < 9 * on.size()) continue;
    Vec centre = Vec::Zero();
    std::size_t inliers = 0;
    for (NodeId n : on)
      if (best.holds(mesh.nodes[n])) centre += mesh.nodes[n], ++inliers;
    centre /= static_cast<double>(inliers);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (NodeId n : on)
      if (best.holds(mesh.nodes[n])) {
        const Vec d = mesh.nodes[n] - centre;
        scatter += d * d.transpose();
      }
    Vec normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
    if (normal.dot(area[p]) < 0.0) normal = -normal;
    // A plane along an image axis keeps its nodes' coordinate exactly.
    for (int k = 0; k < 3; ++k)
      if (std::abs(normal[k]) > 1.0 - 1e-12) normal = Vec::Unit(k) * (normal[k] > 0 ? 1.0 : -1.0);
    const Plane fitted{normal, normal.dot(centre), tolerance};
    if (10 * count_on(fitted) >= 9 * on.size()) planes[p] = fitted;
  }
  return planes;
}

// The cells whose score a step may make the lowest: within this band of it, the worst cell and at
// most this many others (in the node's cell order).
constexpr std::size_t kMaxActive = 12;
constexpr double kActiveBand = 0.2;

// The point of the convex hull of g nearest the origin (zero when the origin is inside): the
// steepest ascent of min_i g_i·d. In three dimensions it lies on a vertex, an edge or a triangle
// of the hull, and it is the candidate p with p·g_i ≥ |p|² for every i.
Vec shortest_in_hull(std::span<const Vec> g) {
  const std::size_t k = g.size();
  double scale = 0.0;
  for (const Vec& v : g) scale = std::max(scale, v.squaredNorm());
  if (!(scale > 0.0)) return Vec::Zero();
  Vec best = Vec::Zero();
  double best_norm = INFINITY;
  auto consider = [&](const Vec& p) {
    const double norm = p.squaredNorm();
    if (norm >= best_norm) return;
    const double slack = 1e-9 * std::sqrt(norm * scale);  // rounding of p·v, relative
    for (const Vec& v : g)
      if (p.dot(v) < norm - slack) return;
    best = p;
    best_norm = norm;
  };
  for (std::size_t i = 0; i < k; ++i) {
    consider(g[i]);
    for (std::size_t j = i + 1; j < k; ++j) {
      const Vec e = g[j] - g[i];
      const double ee = e.squaredNorm();
      if (ee > 0.0) {
        const double t = -g[i].dot(e) / ee;
        if (t > 0.0 && t < 1.0) consider(g[i] + t * e);
      }
      for (std::size_t l = j + 1; l < k; ++l) {
        const Vec f = g[l] - g[i];
        const double ef = e.dot(f), ff = f.squaredNorm();
        const double det = ee * ff - ef * ef;
        if (!(det > 1e-14 * ee * ff)) continue;
        const double re = -g[i].dot(e), rf = -g[i].dot(f);
        const double a = (re * ff - rf * ef) / det, b = (rf * ee - re * ef) / det;
        if (a > 0.0 && b > 0.0 && a + b < 1.0) consider(g[i] + a * e + b * f);
      }
    }
  }
  // A candidate of rounding size is the origin: no direction raises every score.
  return best_norm <= 1e-18 * scale ? Vec::Zero() : best;
}

class Relocator {
 public:
  Relocator(HybridMesh& mesh, const LevelSet* wall, const std::vector<bool>& on_surface,
            const RelocateOptions& options)
      : mesh_(mesh), cells_{mesh}, wall_(wall), score_(options) {
    const std::size_t n_nodes = mesh.nodes.size();
    // A node's patches: none (-1), one, two, or more (the second -2).
    std::vector<std::array<std::int32_t, 2>> patch(n_nodes, {-1, -1});
    for_each_boundary_face(std::as_const(mesh), [&](std::span<const NodeId> f, std::int32_t p) {
      for (NodeId n : f) {
        auto& [a, b] = patch[n];
        if (a == -1 || a == p)
          a = p;
        else if (b == -1 || b == p)
          b = p;
        else
          b = -2;
      }
    });
    const std::vector<Plane> planes = flat_patches(mesh);
    auto walled = [&](std::int32_t p) {
      return static_cast<std::size_t>(p) < on_surface.size() &&
             on_surface[static_cast<std::size_t>(p)];
    };
    // Node n on the plane of flat patch p (a node merged off it stays).
    auto flat = [&](std::int32_t p, std::size_t n) {
      const Plane& plane = planes[static_cast<std::size_t>(p)];
      return !walled(p) && plane.normal.squaredNorm() > 0.0 && plane.holds(mesh.nodes[n]);
    };
    freedom_.assign(n_nodes, Freedom::interior);
    plane_.assign(n_nodes, -1);
    for (std::size_t n = 0; n < n_nodes; ++n) {
      const auto [a, b] = patch[n];
      if (a == -1) continue;
      if (b == -1) {
        freedom_[n] = walled(a)    ? (wall ? Freedom::surface : Freedom::fixed)
                      : flat(a, n) ? Freedom::plane
                                   : Freedom::fixed;
        if (freedom_[n] == Freedom::plane) plane_[n] = a;
      } else if (wall && b >= 0 && ((walled(a) && flat(b, n)) || (flat(a, n) && walled(b)))) {
        freedom_[n] = Freedom::rim;
        plane_[n] = walled(a) ? b : a;
      } else {
        freedom_[n] = Freedom::fixed;
      }
    }
    planes_ = planes;
    // The hexahedra of the interior keep their shape: a node used by hexahedra only stays.
    std::vector<char> other(n_nodes, 0);
    for (const auto& t : mesh.tets)
      for (NodeId n : t) other[n] = 1;
    for (const auto& p : mesh.pyramids)
      for (NodeId n : p) other[n] = 1;
    for (std::size_t n = 0; n < n_nodes; ++n)
      if (!other[n]) freedom_[n] = Freedom::fixed;
    node_cells_.build(n_nodes, cells_.count(), [&](std::size_t c) { return cells_[c]; });
    const std::size_t tris = mesh.boundary_tris.size();
    node_faces_.build(n_nodes, tris + mesh.boundary_quads.size(),
                      [&](std::size_t f) { return face(f); });
    // Rim nodes in a voxel whose corners are all on one side of the wall's level zero.
    std::vector<std::pair<NodeId, std::int32_t>> uses;  // (face neighbour, face patch)
    for (std::size_t n = 0; n < n_nodes; ++n) {
      if (freedom_[n] != Freedom::rim) continue;
      double value;
      Vec gradient;
      if (wall->evaluate(mesh.nodes[n], value, gradient) && gradient.squaredNorm() > 0.0) continue;
      uses.clear();
      for (auto f : node_faces_.of(static_cast<NodeId>(n))) {
        const auto v = face(static_cast<std::size_t>(f));
        const std::size_t i =
            static_cast<std::size_t>(std::find(v.begin(), v.end(), n) - v.begin());
        const std::int32_t p = static_cast<std::size_t>(f) < tris
                                   ? mesh.boundary_tri_patch[static_cast<std::size_t>(f)]
                                   : mesh.boundary_quad_patch[static_cast<std::size_t>(f) - tris];
        uses.push_back({v[(i + 1) % v.size()], p});
        uses.push_back({v[(i + v.size() - 1) % v.size()], p});
      }
      std::sort(uses.begin(), uses.end());
      std::array<NodeId, 2> ends{};
      int count = 0;
      for (std::size_t k = 0; k < uses.size();) {
        std::size_t j = k;
        bool on_wall = false, on_plane = false;
        for (; j < uses.size() && uses[j].first == uses[k].first; ++j) {
          on_wall = on_wall || walled(uses[j].second);
          on_plane = on_plane || uses[j].second == plane_[n];
        }
        if (on_wall && on_plane && count < 3) {
          if (count < 2) ends[static_cast<std::size_t>(count)] = uses[k].first;
          ++count;
        }
        k = j;
      }
      if (count != 2) continue;
      freedom_[n] = Freedom::along;
      rim_ends_[static_cast<NodeId>(n)] = ends;
    }
  }

  RelocateStats run(int sweeps, std::vector<std::int64_t>* unchanged_from) {
    RelocateStats stats;
    const std::size_t n_cells = cells_.count();
    score_of_.resize(n_cells);
    auto at = [&](NodeId n) -> const Vec& { return mesh_.nodes[n]; };
    // A cell without a movable node (most hexahedra) never changes, nor joins the queue.
    for (std::size_t c = 0; c < n_cells; ++c) {
      const auto nodes = cells_[c];
      const bool movable = std::any_of(nodes.begin(), nodes.end(),
                                       [&](NodeId n) { return freedom_[n] != Freedom::fixed; });
      score_of_[c] = movable ? static_cast<float>(score_(nodes, at)) : 1.0f;
    }

    // A node is tried again only after a neighbour moved.
    std::vector<char> moved(mesh_.nodes.size(), 0), stale(mesh_.nodes.size(), 1);
    std::vector<std::pair<float, NodeId>> queue;
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      // The movable nodes of cells below target, worst first, once each.
      queue.clear();
      for (std::size_t c = 0; c < n_cells; ++c)
        if (score_of_[c] < 1.0f)
          for (NodeId n : cells_[c])
            if (freedom_[n] != Freedom::fixed && stale[n]) queue.push_back({score_of_[c], n});
      std::sort(queue.begin(), queue.end());
      std::size_t kept = 0;
      for (const auto& entry : queue)
        if (stale[entry.second]) {
          stale[entry.second] = 0;
          queue[kept++] = entry;
        }
      queue.resize(kept);
      std::size_t moves = 0;
      for (const auto& [worst, n] : queue) {
        if (!improve(n)) continue;
        ++moves;
        moved[n] = 1;
        for (auto c : node_cells_.of(n)) {
          score_of_[c] = static_cast<float>(score_(cells_[c], at));
          for (NodeId m : cells_[c]) stale[m] = 1;
        }
      }
      stats.moves += moves;
      if (moves == 0) break;
    }

    for (std::size_t n = 0; n < moved.size(); ++n) {
      if (!moved[n]) continue;
      ++stats.nodes_moved;
      if (freedom_[n] == Freedom::along) ++stats.rim_slides;
      if (unchanged_from)
        for (auto c : node_cells_.of(static_cast<NodeId>(n)))
          (*unchanged_from)[static_cast<std::size_t>(c)] = -1;
      double value;
      Vec gradient;
      if ((freedom_[n] == Freedom::surface || freedom_[n] == Freedom::rim) &&
          wall_->evaluate(mesh_.nodes[n], value, gradient))
        stats.largest_surface_offset =
            std::max(stats.largest_surface_offset, std::abs(value) / gradient.norm());
    }
    return stats;
  }

 private:
  std::span<const NodeId> face(std::size_t f) const {
    const std::size_t tris = mesh_.boundary_tris.size();
    if (f < tris) return mesh_.boundary_tris[f];
    return mesh_.boundary_quads[f - tris];
  }

  // The lowest score of n's cells with n at p, stopping as soon as one is at or below `floor`;
  // −∞ when a cell that meets the targets would no longer meet them. Cell `first` (one of n's)
  // is scored first: the worst where n stands most often ends the search.
  double worst_around(NodeId n, const Vec& p, double floor, std::int32_t first) const {
    auto at = [&](NodeId m) -> const Vec& { return m == n ? p : mesh_.nodes[m]; };
    double worst = score_(cells_[static_cast<std::size_t>(first)], at);
    if (worst <= floor) return worst;
    for (auto c : node_cells_.of(n)) {
      if (c == first) continue;
      const double s = score_(cells_[static_cast<std::size_t>(c)], at);
      if (s < 1.0 && score_of_[static_cast<std::size_t>(c)] >= 1.0f) return -INFINITY;
      worst = std::min(worst, s);
      if (worst <= floor) break;
    }
    return worst;
  }

  // p brought back onto where a node of this freedom may be (origin: where it stood); false when
  // that fails or lies farther than `reach` from the step's end.
  bool constrain(Freedom freedom, const Plane* plane, const Vec& origin, Vec& p,
                 double reach) const {
    if (freedom == Freedom::surface) return project(*wall_, p, reach);
    p = plane->through(p, origin);
    return freedom == Freedom::plane || project(*wall_, p, reach, plane, origin);
  }

  // The boundary faces around a boundary node keep their orientation (within 60°). A face's
  // vector area is linear in each corner: moving corner i by d adds ½ d × (x[i+1] − x[i−1]).
  bool faces_keep_orientation(NodeId n, const Vec& p) const {
    const auto& x = mesh_.nodes;
    for (auto f : node_faces_.of(n)) {
      const auto v = face(static_cast<std::size_t>(f));
      const std::size_t i = static_cast<std::size_t>(std::find(v.begin(), v.end(), n) - v.begin());
      const Vec before = polygon_vector_area(mesh_, v);
      const Vec after = before + 0.5 * (p - x[n]).cross(x[v[(i + 1) % v.size()]] -
                                                        x[v[(i + v.size() - 1) % v.size()]]);
      if (!(after.dot(before) > 0.5 * after.norm() * before.norm())) return false;
    }
    return true;
  }

  // Pattern search for the position of n that maximizes the lowest score of its cells: the
  // steepest ascent of the lowest score first, then the axes (or, on the wall, two tangents),
  // halving the step when nothing improves. Returns whether n moved.
  bool improve(NodeId n) {
    const auto around = node_cells_.of(n);
    if (around.empty()) return false;
    const Vec origin = mesh_.nodes[n];
    // The mean distance to the other nodes of its cells sets the step sizes.
    double length = 0.0;
    std::size_t neighbours = 0;
    for (auto c : around)
      for (NodeId m : cells_[static_cast<std::size_t>(c)])
        if (m != n) {
          length += (mesh_.nodes[m] - origin).norm();
          ++neighbours;
        }
    length /= static_cast<double>(neighbours);

    Vec x = origin;
    double best = worst_around(n, x, -INFINITY, around[0]);
    if (best >= 1.0) return false;
    const Freedom freedom = freedom_[n];
    if (freedom == Freedom::along) return slide_along_rim(n, best, around[0]);
    const Plane* plane = plane_[n] >= 0 ? &planes_[static_cast<std::size_t>(plane_[n])] : nullptr;
    double h = 0.25 * length;
    bool moved = false;
    for (int iteration = 0; iteration < 12 && h > 1e-3 * length; ++iteration) {
      std::array<Vec, 7> directions;
      int count = 0;
      std::int32_t worst_cell = around[0];
      // The ascent direction of the lowest score: the shortest vector in the convex hull of the
      // (tangential) score gradients of the cells that a step of h could make the worst (the
      // max-min smoothing of Freitag & Ollivier-Gooch); where one cell alone is that low, its
      // gradient. Zero where no direction raises them all: then only the pattern's axes remain.
      {
        auto at = [&](NodeId m) -> const Vec& { return m == n ? x : mesh_.nodes[m]; };
        double worst = INFINITY;
        scores_.clear();
        for (auto c : around) {
          const double s = score_(cells_[static_cast<std::size_t>(c)], at);
          scores_.push_back(s);
          if (s < worst) worst = s, worst_cell = c;
        }
        // The moves n may make: a projection onto its plane, its line, or none.
        Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity();
        if (freedom == Freedom::surface || freedom == Freedom::plane) {
          Vec normal;
          if (plane) {
            normal = plane->normal;
          } else {
            double value;
            if (!wall_->evaluate(x, value, normal) || !(normal.squaredNorm() > 0.0)) return moved;
            normal.normalize();
          }
          tangent -= normal * normal.transpose();
          const Vec t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
          directions = {Vec::Zero(), t1, -t1, t2, -t2, Vec::Zero(), Vec::Zero()};
          count = 5;
        } else if (freedom == Freedom::rim) {
          // Along the line where the wall meets the plane.
          double value;
          Vec wall_normal;
          if (!wall_->evaluate(x, value, wall_normal)) return moved;
          Vec t = plane->normal.cross(wall_normal);
          if (!(t.squaredNorm() > 0.0)) return moved;
          t.normalize();
          tangent = t * t.transpose();
          directions = {Vec::Zero(), t, -t, Vec::Zero(), Vec::Zero(), Vec::Zero(), Vec::Zero()};
          count = 3;
        } else {
          directions = {Vec::Zero(),   Vec::UnitX(), -Vec::UnitX(), Vec::UnitY(),
                        -Vec::UnitY(), Vec::UnitZ(), -Vec::UnitZ()};
          count = 7;
        }
        const double delta = 1e-5 * length;
        gradients_.clear();
        for (std::size_t i = 0; i < around.size(); ++i) {
          const double s = scores_[i];
          if (s > worst + kActiveBand ||
              (gradients_.size() >= kMaxActive && around[i] != worst_cell))
            continue;
          const std::size_t c = static_cast<std::size_t>(around[i]);
          Vec gradient;
          bool inverted = false;  // by the difference step: no gradient
          for (int d = 0; d < 3; ++d) {
            Vec y = x;
            y[d] += delta;
            auto moved_at = [&](NodeId m) -> const Vec& { return m == n ? y : mesh_.nodes[m]; };
            const double stepped = score_(cells_[c], moved_at);
            inverted = inverted || (stepped < 0.0 && s >= 0.0);
            gradient[d] = (stepped - s) / delta;
          }
          if (inverted) continue;
          gradient = tangent * gradient;
          if (around[i] == worst_cell || s - worst <= h * gradient.norm())
            gradients_.push_back(gradient);
        }
        directions[0] = shortest_in_hull(gradients_);
        if (directions[0].squaredNorm() > 0.0)
          directions[0].normalize();
        else
          directions[0] = directions[--count];
      }
      Vec best_position = x;
      bool improved = false;
      for (int d = 0; d < count; ++d) {
        Vec p = x + h * directions[d];
        if (freedom != Freedom::interior &&
            (!constrain(freedom, plane, origin, p, 2.0 * h) || !faces_keep_orientation(n, p)))
          continue;
        const double s = worst_around(n, p, best, worst_cell);
        if (s > best + 1e-9 * std::abs(best) + 1e-12) {
          best = s;
          best_position = p;
          improved = true;
          if (d == 0) break;  // the gradient step worked: take it
        }
      }
      if (improved) {
        x = best_position;
        moved = true;
        if (best >= 1.0) break;
      } else {
        h *= 0.5;
      }
    }
    if (moved) mesh_.nodes[n] = x;
    return moved;
  }

  // The position of n that maximizes the lowest score of its cells on the rim's two edges at n
  // (at most 0.45 of either), in n's plane: a search on the fraction of the way to either end.
  bool slide_along_rim(NodeId n, double best, std::int32_t first) {
    const Vec origin = mesh_.nodes[n];
    const auto [towards, away] = rim_ends_.at(n);
    const Vec forward = mesh_.nodes[towards] - origin, backward = mesh_.nodes[away] - origin;
    const Plane& plane = planes_[static_cast<std::size_t>(plane_[n])];
    auto position = [&](double s) {
      return plane.through(origin + (s >= 0.0 ? s * forward : -s * backward), origin);
    };
    double s = 0.0;
    bool moved = false;
    for (double h = 0.25; h > 1e-3;) {
      bool improved = false;
      for (const double t : {std::min(s + h, 0.45), std::max(s - h, -0.45)}) {
        const Vec p = position(t);
        if (t == s || !faces_keep_orientation(n, p)) continue;
        const double score = worst_around(n, p, best, first);
        if (score > best + 1e-9 * std::abs(best) + 1e-12) {
          best = score;
          s = t;
          improved = true;
        }
      }
      if (improved) {
        moved = true;
        if (best >= 1.0) break;
      } else {
        h *= 0.5;
      }
    }
    if (moved) mesh_.nodes[n] = position(s);
    return moved;
  }

  HybridMesh& mesh_;
  Cells cells_;
  const LevelSet* wall_;
  Scorer score_;
  std::vector<Freedom> freedom_;
  std::vector<std::int32_t> plane_;  // the flat patch of plane and rim nodes
  std::unordered_map<NodeId, std::array<NodeId, 2>> rim_ends_;  // of `along` nodes
  std::vector<Plane> planes_;                                   // of each patch
  NodeIncidence node_cells_, node_faces_;
  std::vector<float> score_of_;  // of every cell with a movable node, as the nodes stand; 1 else
  std::vector<double> scores_;   // of the cells around the node being moved
  std::vector<Vec> gradients_;   // of those that may become its worst
};

// Tetrahedra below target with two or three faces on one surface patch are removed: all their
// nodes lie on the wall, so no relocation can lift them, and the wall is the same surface after
// (its triangulation flips an edge, or loses a cap). Two faces abc, abd: the faces acd and bcd
// become the wall, unless cd is a wall edge already (it would join four faces). Three faces:
// their common node leaves the mesh with the cell, if no other cell uses it.
std::size_t remove_boundary_slivers(HybridMesh& mesh, const std::vector<bool>& on_surface,
                                    const Scorer& score,
                                    std::vector<std::int64_t>* unchanged_from) {
  using Key = std::array<NodeId, 3>;
  auto sorted = [](Key k) {
    std::sort(k.begin(), k.end());
    return k;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return (static_cast<std::size_t>(k[0]) * 0x9E3779B97F4A7C15ull) ^
             (static_cast<std::size_t>(k[1]) * 0xC2B2AE3D27D4EB4Full) ^
             static_cast<std::size_t>(k[2]);
    }
  };
  // Only tetrahedra below target whose nodes are all on the boundary are candidates; find them
  // before building any table.
  std::vector<char> on_boundary(mesh.nodes.size(), 0);
  for (const auto& t : mesh.boundary_tris)
    for (NodeId n : t) on_boundary[n] = 1;
  auto at = [&](NodeId n) -> const Vec& { return mesh.nodes[n]; };
  std::vector<std::size_t> candidates;
  for (std::size_t c = 0; c < mesh.tets.size(); ++c) {
    const auto& t = mesh.tets[c];
    if (on_boundary[t[0]] && on_boundary[t[1]] && on_boundary[t[2]] && on_boundary[t[3]] &&
        score(std::span<const NodeId>(t), at) < 1.0)
      candidates.push_back(c);
  }
  if (candidates.empty()) return 0;

  // Only the candidates' faces and edges are ever looked up: the tables hold those alone.
  std::unordered_set<Key, KeyHash> candidate_face;
  std::unordered_map<std::uint64_t, int> wall_edge;  // boundary triangles on each such edge
  for (std::size_t c : candidates) {
    const auto& t = mesh.tets[c];
    for (const auto& f : kTetFaces)
      candidate_face.insert(sorted({t[f.v[0]], t[f.v[1]], t[f.v[2]]}));
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) wall_edge.emplace(edge_key(t[a], t[b]), 0);
  }
  std::unordered_map<Key, std::int32_t, KeyHash> wall_tri;
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f) {
    const auto& t = mesh.boundary_tris[f];
    if (const Key k = sorted(t); candidate_face.count(k))
      wall_tri[k] = static_cast<std::int32_t>(f);
    for (int k = 0; k < 3; ++k)
      if (const auto it = wall_edge.find(edge_key(t[k], t[(k + 1) % 3])); it != wall_edge.end())
        ++it->second;
  }
  // Cells using each node (for the three-face case).
  std::vector<std::int32_t> uses(mesh.nodes.size(), 0);
  auto count_uses = [&](const auto& cells) {
    for (const auto& c : cells)
      for (NodeId n : c) ++uses[n];
  };
  count_uses(mesh.tets);
  count_uses(mesh.pyramids);
  count_uses(mesh.hexes);

  std::vector<char> removed_tet(mesh.tets.size(), 0), removed_tri(mesh.boundary_tris.size(), 0);
  std::size_t removed = 0;
  for (std::size_t c : candidates) {
    const auto t = mesh.tets[c];
    std::array<std::int32_t, 4> wall_face{-1, -1, -1, -1};
    int on_wall = 0;
    std::int32_t patch = -1;
    bool one_patch = true;
    for (int f = 0; f < 4; ++f) {
      const auto& v = kTetFaces[f].v;
      const auto it = wall_tri.find(sorted({t[v[0]], t[v[1]], t[v[2]]}));
      if (it == wall_tri.end()) continue;
      wall_face[f] = it->second;
      const std::int32_t p = mesh.boundary_tri_patch[static_cast<std::size_t>(it->second)];
      one_patch = one_patch && (patch < 0 || p == patch);
      patch = p;
      ++on_wall;
    }
    if (on_wall < 2 || on_wall > 3 || !one_patch || !on_surface[static_cast<std::size_t>(patch)])
      continue;
    // The faces that become wall, reversed to face out of the remaining cells.
    std::array<Key, 2> fresh;
    int n_fresh = 0;
    Vec old_normal = Vec::Zero();
    for (int f = 0; f < 4; ++f) {
      const auto& v = kTetFaces[f].v;
      const Vec normal = (at(t[v[1]]) - at(t[v[0]])).cross(at(t[v[2]]) - at(t[v[0]]));
      if (wall_face[f] >= 0)
        old_normal += normal;
      else
        fresh[static_cast<std::size_t>(n_fresh++)] = {t[v[0]], t[v[2]], t[v[1]]};
    }
    bool ok = true;
    for (int f = 0; f < n_fresh; ++f) {
      const Key& k = fresh[static_cast<std::size_t>(f)];
      const Vec normal = (at(k[1]) - at(k[0])).cross(at(k[2]) - at(k[0]));
      ok = ok && normal.dot(old_normal) > 0.0;
    }
    if (on_wall == 2) {
      // The edge of the two fresh faces must not be a wall edge yet.
      const Key& k0 = fresh[0];
      const Key& k1 = fresh[1];
      std::array<NodeId, 2> shared{};
      int n_shared = 0;
      for (NodeId a : k0)
        if (std::find(k1.begin(), k1.end(), a) != k1.end() && n_shared < 2) shared[n_shared++] = a;
      const auto it = wall_edge.find(edge_key(shared[0], shared[1]));
      ok = ok && n_shared == 2 && (it == wall_edge.end() || it->second == 0);
    } else {
      // The node common to the three wall faces goes with the cell.
      NodeId apex = -1;
      for (NodeId n : t) {
        bool in_all = true;
        for (int f = 0; f < 4; ++f)
          if (wall_face[f] < 0) {
            const auto& v = kTetFaces[f].v;
            in_all = in_all && (t[v[0]] == n || t[v[1]] == n || t[v[2]] == n);
          }
        if (!in_all) apex = n;  // the one node missing from the fresh face
      }
      ok = ok && apex >= 0 && uses[apex] == 1;
    }
    if (!ok) continue;

    removed_tet[c] = 1;
    ++removed;
    for (NodeId n : t) --uses[n];
    for (int f = 0; f < 4; ++f) {
      if (wall_face[f] < 0) continue;
      const auto& tri = mesh.boundary_tris[static_cast<std::size_t>(wall_face[f])];
      removed_tri[static_cast<std::size_t>(wall_face[f])] = 1;
      wall_tri.erase(sorted(tri));
      for (int k = 0; k < 3; ++k) --wall_edge[edge_key(tri[k], tri[(k + 1) % 3])];
    }
    for (int f = 0; f < n_fresh; ++f) {
      const Key& k = fresh[static_cast<std::size_t>(f)];
      wall_tri[sorted(k)] = static_cast<std::int32_t>(mesh.boundary_tris.size());
      mesh.boundary_tris.push_back(k);
      mesh.boundary_tri_patch.push_back(patch);
      removed_tri.push_back(0);
      for (int e = 0; e < 3; ++e) ++wall_edge[edge_key(k[e], k[(e + 1) % 3])];
    }
  }
  if (removed == 0) return 0;

  // The removed tetrahedra leave the cell list (and unchanged_from, whose first entries are
  // the tetrahedra), the removed triangles the boundary.
  std::size_t kept = 0;
  for (std::size_t c = 0; c < mesh.tets.size(); ++c) {
    if (removed_tet[c]) continue;
    mesh.tets[kept] = mesh.tets[c];
    if (unchanged_from) (*unchanged_from)[kept] = (*unchanged_from)[c];
    ++kept;
  }
  if (unchanged_from)
    unchanged_from->erase(unchanged_from->begin() + static_cast<std::ptrdiff_t>(kept),
                          unchanged_from->begin() + static_cast<std::ptrdiff_t>(mesh.tets.size()));
  mesh.tets.resize(kept);
  kept = 0;
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f) {
    if (removed_tri[f]) continue;
    mesh.boundary_tris[kept] = mesh.boundary_tris[f];
    mesh.boundary_tri_patch[kept] = mesh.boundary_tri_patch[f];
    ++kept;
  }
  mesh.boundary_tris.resize(kept);
  mesh.boundary_tri_patch.resize(kept);
  compact_nodes(mesh);
  return removed;
}

// The triangulations of a convex polygon with corners 0 … m−1 (m ≤ kMaxRing), as lists of
// corner triples in the polygon's order.
constexpr int kMaxRing = 7;
using Triangulation = std::vector<std::array<int, 3>>;
void triangulate(int first, int last, Triangulation& partial, std::vector<Triangulation>& all,
                 std::vector<std::pair<int, int>>& pending) {
  if (last - first < 2) {
    if (pending.empty()) {
      all.push_back(partial);
      return;
    }
    const auto [f, l] = pending.back();
    pending.pop_back();
    triangulate(f, l, partial, all, pending);
    pending.push_back({f, l});
    return;
  }
  for (int k = first + 1; k < last; ++k) {
    partial.push_back({first, k, last});
    pending.push_back({k, last});
    triangulate(first, k, partial, all, pending);
    pending.pop_back();
    partial.pop_back();
  }
}
const std::vector<Triangulation>& triangulations(int m) {
  static const auto table = [] {
    std::array<std::vector<Triangulation>, kMaxRing + 1> t;
    for (int size = 3; size <= kMaxRing; ++size) {
      Triangulation partial;
      std::vector<std::pair<int, int>> pending;
      triangulate(0, size - 1, partial, t[static_cast<std::size_t>(size)], pending);
    }
    return t;
  }();
  return table[static_cast<std::size_t>(m)];
}

// Edge removal (Shewchuk 2002): the m tetrahedra around an interior edge u–v whose cells are all
// tetrahedra (3 ≤ m ≤ 7) become 2(m − 2): the ring of their other nodes triangulated, each
// triangle joined to u and to v. Taken for an edge of a tetrahedron below target when every new
// cell is positive and the worst of them scores better than the worst of the old; the best
// triangulation and the best edge of the cell win. The union, and so every boundary face, is
// unchanged. One sweep; cells changed once are not changed again.
std::size_t remove_edges(HybridMesh& mesh, const Scorer& score,
                         std::vector<std::int64_t>* unchanged_from) {
  using Tet = std::array<NodeId, 4>;
  auto at = [&](NodeId n) -> const Vec& { return mesh.nodes[n]; };
  auto tet_score = [&](const Tet& t) { return score(std::span<const NodeId>(t), at); };
  const std::size_t n_tets = mesh.tets.size();
  std::vector<std::size_t> candidates;
  for (std::size_t c = 0; c < n_tets; ++c)
    if (tet_score(mesh.tets[c]) < 1.0) candidates.push_back(c);
  if (candidates.empty()) return 0;
  NodeIncidence node_tets;
  node_tets.build(mesh.nodes.size(), n_tets, [&](std::size_t c) { return mesh.tets[c]; });

  std::vector<char> touched(n_tets, 0), gone(n_tets, 0);
  std::vector<Tet> fresh_best, fresh;
  std::vector<std::int32_t> ring_best, ring_cells;
  std::array<NodeId, kMaxRing> ring{};
  std::size_t removals = 0;
  for (std::size_t c : candidates) {
    if (touched[c]) continue;
    const Tet t = mesh.tets[c];
    double best_gain = 0.0;
    fresh_best.clear();
    ring_best.clear();
    for (int e = 0; e < 6; ++e) {
      const NodeId u = t[kTetEdges[e][0]], v = t[kTetEdges[e][1]];
      // The tetrahedra around u–v, each giving the ring a directed edge x → y with (u, v, x, y)
      // positive. Around a boundary edge, or one a pyramid or hexahedron shares, they leave a
      // gap and the ring does not close.
      ring_cells.clear();
      std::array<std::pair<NodeId, NodeId>, kMaxRing> links{};
      bool usable = true;
      for (auto k : node_tets.of(u)) {
        const Tet& w = mesh.tets[static_cast<std::size_t>(k)];
        if (std::find(w.begin(), w.end(), v) == w.end()) continue;
        // The ring's direction comes from the cells' volumes, so an inverted or flat one
        // (which could reverse it) keeps the edge.
        if (touched[static_cast<std::size_t>(k)] || ring_cells.size() == kMaxRing ||
            !(tet_volume(at(w[0]), at(w[1]), at(w[2]), at(w[3])) > 0.0)) {
          usable = false;
          break;
        }
        std::array<NodeId, 2> other{};
        int n_other = 0;
        for (NodeId x : w)
          if (x != u && x != v) other[n_other++] = x;
        if (tet_volume(at(u), at(v), at(other[0]), at(other[1])) < 0.0)
          std::swap(other[0], other[1]);
        links[ring_cells.size()] = {other[0], other[1]};
        ring_cells.push_back(k);
      }
      const int m = static_cast<int>(ring_cells.size());
      if (!usable || m < 3) continue;
      // Chain the links into one closed ring of m nodes.
      ring[0] = links[0].first;
      bool closed = true;
      for (int i = 1; i <= m && closed; ++i) {
        const NodeId from = ring[static_cast<std::size_t>(i - 1)];
        int next = -1;
        for (int j = 0; j < m; ++j)
          if (links[static_cast<std::size_t>(j)].first == from) next = j;
        if (next < 0) {
          closed = false;
          break;
        }
        const NodeId to = links[static_cast<std::size_t>(next)].second;
        if (i == m)
          closed = to == ring[0];
        else
          ring[static_cast<std::size_t>(i)] = to;
      }
      if (!closed) continue;
      double worst_old = INFINITY;
      for (auto k : ring_cells) worst_old = std::min(worst_old, tet_score(mesh.tets[k]));
      for (const auto& tri : triangulations(m)) {
        fresh.clear();
        double worst_new = INFINITY;
        for (const auto& [i, j, k] : tri) {
          const NodeId a = ring[static_cast<std::size_t>(i)], b = ring[static_cast<std::size_t>(j)],
                       d = ring[static_cast<std::size_t>(k)];
          // The ring runs counterclockwise seen from v ((u, v, x, y) positive), so the triangle
          // (a, b, d) faces v: (a, b, d, v) and (d, b, a, u) are positive.
          fresh.push_back({a, b, d, v});
          fresh.push_back({d, b, a, u});
        }
        for (const Tet& n : fresh) {
          worst_new = std::min(worst_new, tet_score(n));
          if (!(worst_new - worst_old > best_gain)) break;
        }
        if (worst_new - worst_old > best_gain) {
          best_gain = worst_new - worst_old;
          fresh_best = fresh;
          ring_best = ring_cells;
        }
      }
    }
    if (fresh_best.empty()) continue;
    std::size_t next = 0;
    for (auto k : ring_best) {
      const auto slot = static_cast<std::size_t>(k);
      touched[slot] = 1;
      if (next < fresh_best.size())
        mesh.tets[slot] = fresh_best[next++];
      else
        gone[slot] = 1;
    }
    for (; next < fresh_best.size(); ++next) {
      mesh.tets.push_back(fresh_best[next]);
      touched.push_back(1);
      gone.push_back(0);
    }
    ++removals;
  }
  if (removals == 0) return 0;
  // Removed slots leave; every changed or new tetrahedron is "changed" for the quality report.
  std::vector<std::int64_t> from;
  std::size_t kept = 0;
  for (std::size_t c = 0; c < mesh.tets.size(); ++c) {
    if (gone[c]) continue;
    if (unchanged_from) from.push_back(touched[c] ? -1 : (*unchanged_from)[c]);
    mesh.tets[kept++] = mesh.tets[c];
  }
  mesh.tets.resize(kept);
  if (unchanged_from) {
    from.insert(from.end(), unchanged_from->begin() + static_cast<std::ptrdiff_t>(n_tets),
                unchanged_from->end());
    *unchanged_from = std::move(from);
  }
  return removals;
}

// How many cells are below target, and the lowest score.
void summarize(const HybridMesh& mesh, const Scorer& score, std::size_t& below, double& worst) {
  const Cells cells{mesh};
  auto at = [&](NodeId n) -> const Vec& { return mesh.nodes[n]; };
  below = 0;
  worst = INFINITY;
  for (std::size_t c = 0; c < cells.count(); ++c) {
    const double s = score(cells[c], at);
    below += s < 1.0;
    worst = std::min(worst, s);
  }
}

}  // namespace

RelocateStats relocate_nodes(HybridMesh& mesh, const LevelSet* wall,
                             const std::vector<bool>& on_surface, const RelocateOptions& options,
                             std::vector<std::int64_t>* unchanged_from) {
  Stopwatch clock;
  const Scorer score(options);
  std::size_t below_before;
  double worst_before;
  summarize(mesh, score, below_before, worst_before);
  std::size_t removed = remove_boundary_slivers(mesh, on_surface, score, unchanged_from);
  RelocateStats stats =
      Relocator(mesh, wall, on_surface, options).run(options.sweeps, unchanged_from);
  stats.edges_removed = remove_edges(mesh, score, unchanged_from);
  removed += remove_boundary_slivers(mesh, on_surface, score, unchanged_from);
  stats.slivers_removed = removed;
  stats.cells_below_before = below_before;
  stats.worst_before = worst_before;
  summarize(mesh, score, stats.cells_below_after, stats.worst_after);
  stats.seconds = clock.seconds();
  return stats;
}

}  // namespace naris
