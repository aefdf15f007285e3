#include "solver/particles/release.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/units.h"

namespace naris::particles {
namespace {

double segment_distance(const Vec3& x, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double l2 = d.squaredNorm();
  const double t = l2 > 0.0 ? std::clamp((x - a).dot(d) / l2, 0.0, 1.0) : 0.0;
  return (x - (a + t * d)).norm();
}

// Uniform in [0, 1) from 53 bits: the same sequence from every standard library.
double uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

int group_id(ReleaseSet& set, const std::string& name) {
  for (std::size_t g = 0; g < set.groups.size(); ++g)
    if (set.groups[g] == name) return static_cast<int>(g);
  set.groups.push_back(name);
  return static_cast<int>(set.groups.size()) - 1;
}

// A boundary face as triangles the way the tracker splits it (mesh_flow.h): a quadrilateral
// along the diagonal through its lowest node, so points placed on them lie on its faces.
template <class F>
void tracker_triangles(std::span<const NodeId> ids, F&& triangle) {
  const std::size_t n = ids.size(),
                    o = n == 4 ? static_cast<std::size_t>(std::min_element(ids.begin(), ids.end()) -
                                                          ids.begin())
                               : 0;
  for (std::size_t k = 1; k + 1 < n; ++k) triangle(ids[o], ids[(o + k) % n], ids[(o + k + 1) % n]);
}

// Triangles tilted more than this from the patch's plane (|n̂·normal| below it) are folds that
// no point projects onto.
constexpr double kFacing = 0.1;

}  // namespace

const std::array<Vec3, 3>* InletShape::triangle_under(const Vec3& x) const {
  // Along the patch's normal: the triangles' projections on its plane tile the patch.
  for (const auto& t : triangles) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
    const double a = n.norm();
    if (!(n.dot(normal) > kFacing * a)) continue;
    bool inside = true;
    for (int k = 0; k < 3 && inside; ++k) {
      const Vec3& p = t[static_cast<std::size_t>(k)];
      const Vec3& q = t[static_cast<std::size_t>((k + 1) % 3)];
      inside = (q - p).cross(x - p).dot(normal) >= -1e-12 * a;
    }
    if (inside) return &t;
  }
  return nullptr;
}

bool InletShape::contains(const Vec3& x) const {
  return triangle_under(x) != nullptr;
}

Vec3 InletShape::onto_patch(const Vec3& x) const {
  const std::array<Vec3, 3>* t = triangle_under(x);
  if (!t) return x;
  const Vec3 n = ((*t)[1] - (*t)[0]).cross((*t)[2] - (*t)[0]);
  return x + ((*t)[0] - x).dot(n) / normal.dot(n) * normal;  // n·normal > kFacing |n|
}

int seed_inside(const InletShape& inlet, const FlowDomain& domain, Vec3& x) {
  const Vec3 on = inlet.onto_patch(x);
  double step = 1e-7;
  for (int k = 0; k <= 5; ++k, step *= 4.0) {  // 0.1 µm … 0.1024 mm
    const int cell = domain.locate(on - step * inlet.normal);
    if (cell >= 0) {
      x = on - step * inlet.normal;
      return cell;
    }
  }
  return -1;
}

double InletShape::distance_to_outline(const Vec3& x) const {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& e : outline) d = std::min(d, segment_distance(x, e[0], e[1]));
  return d;
}

InletShape inlet_shape(const HybridMesh& mesh, int patch, const Vec3& up) {
  InletShape s;
  Vec3 vector_area = Vec3::Zero(), first = Vec3::Zero();
  std::map<std::pair<NodeId, NodeId>, int> edges;  // undirected edge → uses
  for_each_boundary_face(mesh, [&](std::span<const NodeId> ids, std::int32_t p) {
    if (p != patch) return;
    tracker_triangles(ids, [&](NodeId a, NodeId b, NodeId c) {
      s.triangles.push_back({mesh.nodes[a] * kMm, mesh.nodes[b] * kMm, mesh.nodes[c] * kMm});
    });
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const NodeId a = ids[k], b = ids[(k + 1) % ids.size()];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  });
  if (s.triangles.empty()) fail("the inlet patch has no faces");
  for (const auto& t : s.triangles) {
    const Vec3 a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]);
    vector_area += a;
    first += a.norm() * (t[0] + t[1] + t[2]) / 3.0;
    s.area += a.norm();
  }
  s.centre = first / s.area;
  s.normal = vector_area.normalized();
  for (const auto& [e, uses] : edges)
    if (uses == 1) s.outline.push_back({mesh.nodes[e.first] * kMm, mesh.nodes[e.second] * kMm});
  // Second moments of the area about the centre (vertices and centroid of each triangle).
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const auto& t : s.triangles) {
    const double a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
    const Vec3 c = (t[0] + t[1] + t[2]) / 3.0 - s.centre;
    m += a * c * c.transpose();
    for (const Vec3& v : t) m += (a / 12.0) * (v - s.centre - c) * (v - s.centre - c).transpose();
  }
  const Eigen::Matrix3d project = Eigen::Matrix3d::Identity() - s.normal * s.normal.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(project * m * project);
  const Vec3 up_in_plane = project * up;
  const bool round = eig.eigenvalues()[2] < 1.2 * eig.eigenvalues()[1];
  s.long_axis = (round && up_in_plane.norm() > 1e-6) ? Vec3(up_in_plane.normalized())
                                                     : Vec3(eig.eigenvectors().col(2));
  // Up: the end of the axis against gravity; with "up" across the naris plane, the sign that
  // makes the axis's largest component positive (a fixed choice, not anatomy).
  if (std::abs(s.long_axis.dot(up)) > 1e-3) {
    if (s.long_axis.dot(up) < 0.0) s.long_axis = -s.long_axis;
  } else {
    Eigen::Index largest = 0;
    s.long_axis.cwiseAbs().maxCoeff(&largest);
    if (s.long_axis[largest] < 0.0) s.long_axis = -s.long_axis;
  }
  s.short_axis = s.normal.cross(s.long_axis).normalized();
  return s;
}

ReleaseSet dissertation_groups(const InletShape& inlet, double offset, int count) {
  if (count < 1) fail("a release group needs at least one particle (got {})", count);
  double reach = 0.0;
  for (const auto& e : inlet.outline)
    for (const Vec3& v : e) reach = std::max(reach, (v - inlet.centre).norm());
  // The longest run of the long axis whose points lie on the naris at least `offset` from its
  // outline (a non-convex naris may have several).
  const int samples = 2000;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, run_lo = 0.0;
  bool in_run = false;
  for (int i = 0; i <= samples + 1; ++i) {
    const double s = -reach + 2.0 * reach * i / samples;
    const Vec3 x = inlet.centre + s * inlet.long_axis;
    const bool valid = i <= samples && inlet.contains(x) && inlet.distance_to_outline(x) >= offset;
    if (valid && !in_run) run_lo = s;
    if (!valid && in_run) {
      const double run_hi = -reach + 2.0 * reach * (i - 1) / samples;
      if (!(lo <= hi) || run_hi - run_lo > hi - lo) lo = run_lo, hi = run_hi;
    }
    in_run = valid;
  }
  if (!(lo <= hi))
    fail(
        "the inlet is too small for release groups {:.3g} mm from its wall (its long axis spans "
        "{:.3g} mm)",
        offset / kMm, 2.0 * reach / kMm);
  ReleaseSet set;
  set.groups = {"ventral-tip", "midline", "dorsal-tip"};
  const double tip = (hi - lo) / 6.0;
  const double from[3] = {lo, lo, hi - tip}, to[3] = {lo + tip, hi, hi};
  for (int g = 0; g < 3; ++g)
    for (int i = 0; i < count; ++i) {
      const double f = count == 1 ? 0.5 : static_cast<double>(i) / (count - 1);
      set.add(inlet.centre + (from[g] + f * (to[g] - from[g])) * inlet.long_axis, g);
    }
  return set;
}

ReleaseSet grid_release(const InletShape& inlet, int across, double offset) {
  if (across < 1) fail("a release grid needs at least one point across (got {})", across);
  double lo[2] = {0, 0}, hi[2] = {0, 0};
  for (const auto& e : inlet.outline)
    for (const Vec3& v : e) {
      const double a = (v - inlet.centre).dot(inlet.long_axis),
                   b = (v - inlet.centre).dot(inlet.short_axis);
      lo[0] = std::min(lo[0], a), hi[0] = std::max(hi[0], a);
      lo[1] = std::min(lo[1], b), hi[1] = std::max(hi[1], b);
    }
  const double step = (hi[0] - lo[0]) / across;
  ReleaseSet set;
  set.groups = {"grid"};
  for (double b = lo[1] + 0.5 * step; b < hi[1]; b += step)
    for (double a = lo[0] + 0.5 * step; a < hi[0]; a += step) {
      const Vec3 x = inlet.centre + a * inlet.long_axis + b * inlet.short_axis;
      if (inlet.contains(x) && inlet.distance_to_outline(x) >= offset) set.add(x, 0);
    }
  if (set.points.empty())
    fail("no point of a {}-point grid lies on the inlet {:.3g} mm from its wall", across,
         offset / kMm);
  return set;
}

ReleaseSet line_release(const Vec3& a, const Vec3& b, int count) {
  if (count < 1) fail("a release line needs at least one point (got {})", count);
  ReleaseSet set;
  set.groups = {"line"};
  for (int i = 0; i < count; ++i)
    set.add(count == 1 ? Vec3(0.5 * (a + b))
                       : Vec3(a + (b - a) * (static_cast<double>(i) / (count - 1))),
            0);
  return set;
}

ReleaseSet flux_weighted_release(const HybridMesh& mesh, int patch, std::span<const Vec3> velocity,
                                 int count, std::uint64_t seed) {
  if (count < 1) fail("flux-weighted release needs at least one particle (got {})", count);
  // The patch's triangles (split as the tracker's) with their inflow at the corners: density ∝
  // −u·n, linear. A triangle is drawn by area × its largest corner inflow, then a uniform point in
  // it is kept with probability inflow / largest: together ∝ the inflow.
  struct Triangle {
    std::array<NodeId, 3> v;
    std::array<double, 3> inflow;
    double weight;
  };
  std::vector<Triangle> tris;
  std::vector<double> cumulative;
  double total = 0.0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> ids, std::int32_t p) {
    if (p != patch) return;
    const Vec3 n = polygon_vector_area(mesh, ids).normalized();
    tracker_triangles(ids, [&](NodeId a, NodeId b, NodeId c) {
      Triangle t{{a, b, c}, {}, 0.0};
      for (int k = 0; k < 3; ++k)
        t.inflow[k] = std::max(0.0, -velocity[static_cast<std::size_t>(t.v[k])].dot(n));
      const double area = 0.5 * (mesh.nodes[t.v[1]] - mesh.nodes[t.v[0]])
                                    .cross(mesh.nodes[t.v[2]] - mesh.nodes[t.v[0]])
                                    .norm();
      t.weight = area * std::max({t.inflow[0], t.inflow[1], t.inflow[2]});
      if (t.weight <= 0.0) return;
      total += t.weight;
      tris.push_back(t);
      cumulative.push_back(total);
    });
  });
  if (!(total > 0.0)) fail("no air flows in through the inlet: nothing to weight the release by");
  std::mt19937_64 rng(seed);
  ReleaseSet set;
  set.groups = {"flux-weighted"};
  while (static_cast<int>(set.points.size()) < count) {
    const double pick = uniform(rng) * total;
    const std::size_t i = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                                 cumulative.begin()),
        tris.size() - 1);
    const Triangle& t = tris[i];
    double r1 = uniform(rng), r2 = uniform(rng);
    if (r1 + r2 > 1.0) r1 = 1.0 - r1, r2 = 1.0 - r2;
    const double w[3] = {1.0 - r1 - r2, r1, r2};
    const double top = std::max({t.inflow[0], t.inflow[1], t.inflow[2]});
    const double here = w[0] * t.inflow[0] + w[1] * t.inflow[1] + w[2] * t.inflow[2];
    if (uniform(rng) * top > here) continue;
    Vec3 x = Vec3::Zero();
    for (int c = 0; c < 3; ++c) x += w[c] * mesh.nodes[t.v[c]];
    set.add(x * kMm, 0);
  }
  return set;
}

ReleaseSet read_release_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail("{}: cannot read the release points", path);
  ReleaseSet set;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    double x, y, z;
    if (!(fields >> x >> y >> z)) {
      if (number == 1) continue;  // a header
      fail("{}:{}: expected x,y,z in millimetres", path, number);
    }
    std::string group;
    if (!(fields >> group)) group = "points";
    set.add(Vec3(x, y, z) * kMm, group_id(set, group));
  }
  if (set.points.empty()) fail("{}: no release points", path);
  return set;
}

}  // namespace naris::particles
