#include "solver/particles/mesh_flow.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/units.h"
#include "solver/fem/reference_element.h"

namespace naris::particles {
namespace {

// A walk that has not ended after this many cells runs along a face or an edge: it gives up,
// and the tracker retries a shorter step.
constexpr int kMaxWalk = 100000;

// A face as its sorted node ids (a triangle's fourth is the largest id), and who owns it:
// 8·cell + local face, or −1 − boundary face.
struct FaceEntry {
  std::array<NodeId, 4> key;
  std::int64_t owner;
};

std::array<NodeId, 4> face_key(std::span<const NodeId> ids) {
  std::array<NodeId, 4> k{ids[0], ids[1], ids[2],
                          ids.size() == 4 ? ids[3] : std::numeric_limits<NodeId>::max()};
  std::sort(k.begin(), k.end());
  return k;
}

// Shape values (and with `gradient`, their physical gradients) at x, whose reference point
// Newton's method on x(ξ) = x finds from ξ0; an affine cell needs one step.
template <class Element, int N>
void inverse_map(const Eigen::Matrix<double, N, 3>& X, const Vec3& x, Vec3 xi, bool affine,
                 Eigen::Matrix<double, N, 1>& value, Eigen::Matrix<double, N, 3>* gradient) {
  for (int it = 0; it < 20; ++it) {
    const auto s = Element::shape(xi);
    const Vec3 r = x - X.transpose() * s.value;
    const Vec3 step = (X.transpose() * s.gradient).inverse() * r;
    xi += step;
    xi = xi.cwiseMax(-3.0).cwiseMin(3.0);  // a point far outside must not send Newton away
    if constexpr (N == 5) xi[2] = std::min(xi[2], 1.0 - 1e-9);
    if (affine || step.squaredNorm() < 1e-24) break;
  }
  const auto s = Element::shape(xi);
  value = s.value;
  if (gradient) *gradient = s.gradient * (X.transpose() * s.gradient).inverse();
}

// Triangle `half` of a cell's local face, counter-clockwise seen from outside; a quadrilateral
// is split along the diagonal through its lowest node id, the same split from both sides.
std::array<NodeId, 3> face_triangle(std::span<const NodeId> ids, const CellFace& face, int half) {
  const auto& v = face.v;
  if (face.size == 3) return {ids[v[0]], ids[v[1]], ids[v[2]]};
  const std::array<NodeId, 4> q{ids[v[0]], ids[v[1]], ids[v[2]], ids[v[3]]};
  const std::size_t m = static_cast<std::size_t>(std::min_element(q.begin(), q.end()) - q.begin());
  auto corner = [&](std::size_t k) { return q[(m + k) % 4]; };
  if (half == 0) return {corner(0), corner(1), corner(2)};
  return {corner(0), corner(2), corner(3)};
}

}  // namespace

MeshFlow::MeshFlow(const HybridMesh& mesh, std::span<const Vec3> velocity,
                   const std::vector<int>& open_patches)
    : patch_names_(mesh.patch_names) {
  if (velocity.size() != mesh.nodes.size())
    fail("the velocity has {} nodes, the mesh {}", velocity.size(), mesh.nodes.size());
  nodes_.resize(mesh.nodes.size());
  velocity_.resize(mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    nodes_[i] = mesh.nodes[i] * kMm;
    velocity_[i] = velocity[i];
  }
  const std::size_t n = mesh.cell_count();
  nodes_of_.assign(8 * n, -1);
  count_.resize(n);
  size_.resize(n);
  std::size_t c = 0;
  auto add = [&](std::span<const NodeId> ids, double volume_mm3) {
    std::copy(ids.begin(), ids.end(), &nodes_of_[8 * c]);
    count_[c] = static_cast<std::int8_t>(ids.size());
    size_[c] = static_cast<float>(std::cbrt(std::abs(volume_mm3)) * kMm);
    ++c;
  };
  for (const auto& t : mesh.tets)
    add(t, tet_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]));
  for (const auto& p : mesh.pyramids) add(p, pyramid_volume(mesh, p));
  for (const auto& h : mesh.hexes) add(h, hex_volume(mesh, h));
  // Parallelepipeds (MVE's interior cubes): the trilinear map is affine, x = centre + J₀ξ.
  affine_.assign(n, 0);
  const std::size_t first_hex = mesh.tets.size() + mesh.pyramids.size();
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    Eigen::Matrix<double, 8, 3> X;
    for (int i = 0; i < 8; ++i)
      X.row(i) = nodes_[static_cast<std::size_t>(mesh.hexes[h][i])].transpose();
    const auto s0 = fem::Hex8::shape(Vec3::Zero());
    const Vec3 centre = X.transpose() * s0.value;
    const Eigen::Matrix3d J = X.transpose() * s0.gradient;
    double misfit = 0.0;
    for (int i = 0; i < 8; ++i)
      misfit = std::max(misfit, (X.row(i).transpose() - centre - J * fem::Hex8::node(i)).norm());
    affine_[first_hex + h] = misfit <= 1e-9 * size_[first_hex + h];
  }

  // Face planes; a quadrilateral is split along the diagonal through its lowest node id.
  plane_start_.resize(n + 1);
  plane_start_[0] = 0;
  for (std::size_t cell = 0; cell < n; ++cell) {
    const auto ids = cell_nodes(static_cast<int>(cell));
    std::uint32_t count = 0;
    for (const CellFace& f : cell_faces(static_cast<int>(ids.size()))) count += f.size == 3 ? 1 : 2;
    plane_start_[cell + 1] = plane_start_[cell] + count;
  }
  planes_.resize(plane_start_[n]);
  for (std::size_t cell = 0; cell < n; ++cell) {
    const auto ids = cell_nodes(static_cast<int>(cell));
    const auto local = cell_faces(static_cast<int>(ids.size()));
    std::size_t at = plane_start_[cell];
    auto add_plane = [&](std::size_t f, int half, NodeId a, NodeId b, NodeId d) {
      const Vec3& pa = nodes_[static_cast<std::size_t>(a)];
      const Vec3 normal = (nodes_[static_cast<std::size_t>(b)] - pa)
                              .cross(nodes_[static_cast<std::size_t>(d)] - pa)
                              .normalized();
      Plane& p = planes_[at++];
      p.unit = {static_cast<float>(normal[0]), static_cast<float>(normal[1]),
                static_cast<float>(normal[2])};
      p.offset = p.n().dot(pa);
      p.face = static_cast<std::int8_t>(f);
      p.half = static_cast<std::int8_t>(half);
    };
    for (std::size_t f = 0; f < local.size(); ++f) {
      for (int half = 0; half < (local[f].size == 3 ? 1 : 2); ++half) {
        const auto t = face_triangle(ids, local[f], half);
        add_plane(f, half, t[0], t[1], t[2]);
      }
    }
  }

  // Convex cells with plane faces: no node outside the plane of a face triangle, none of a face
  // off it, by more than rounding.
  convex_.assign(n, 1);
  for (std::size_t cell = 0; cell < n; ++cell) {
    const auto ids = cell_nodes(static_cast<int>(cell));
    if (ids.size() == 4) continue;
    const auto local = cell_faces(static_cast<int>(ids.size()));
    for (const Plane& p : planes_of(static_cast<int>(cell))) {
      const auto tri = triangle(static_cast<int>(cell), p);
      const Vec3& p0 = nodes_[static_cast<std::size_t>(tri[0])];
      const Vec3 normal = (nodes_[static_cast<std::size_t>(tri[1])] - p0)
                              .cross(nodes_[static_cast<std::size_t>(tri[2])] - p0)
                              .normalized();
      const double tolerance = 1e-9 * size_[cell];
      for (NodeId v : ids)
        if (normal.dot(nodes_[static_cast<std::size_t>(v)] - p0) > tolerance) convex_[cell] = 0;
      const CellFace& f = local[static_cast<std::size_t>(p.face)];
      for (int k = 0; k < f.size; ++k)
        if (normal.dot(nodes_[static_cast<std::size_t>(ids[f.v[k]])] - p0) < -tolerance)
          convex_[cell] = 0;
    }
  }

  // Face neighbours: every cell face meets one other cell face or one boundary face.
  std::vector<FaceEntry> faces;
  faces.reserve(6 * n + mesh.boundary_tris.size() + mesh.boundary_quads.size());
  for (std::size_t cell = 0; cell < n; ++cell) {
    const auto ids = cell_nodes(static_cast<int>(cell));
    const auto local = cell_faces(static_cast<int>(ids.size()));
    for (std::size_t f = 0; f < local.size(); ++f) {
      std::array<NodeId, 4> v{};
      for (int k = 0; k < local[f].size; ++k) v[static_cast<std::size_t>(k)] = ids[local[f].v[k]];
      faces.push_back({face_key(std::span<const NodeId>(v.data(), local[f].size)),
                       static_cast<std::int64_t>(8 * cell + f)});
    }
  }
  std::int64_t b = 0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> ids, std::int32_t patch) {
    faces.push_back({face_key(ids), -1 - b++});
    boundary_patch_.push_back(patch);
  });
  std::sort(faces.begin(), faces.end(), [](const FaceEntry& x, const FaceEntry& y) {
    return x.key != y.key ? x.key < y.key : x.owner > y.owner;
  });
  neighbour_.assign(6 * n, std::numeric_limits<std::int32_t>::min());
  neighbour_face_.assign(6 * n, -1);
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    const FaceEntry& first = faces[i];
    if (j - i != 2 || first.owner < 0)
      fail(
          "the mesh is not closed: a face of nodes {} {} {} is shared by {} cells and boundary "
          "faces",
          first.key[0], first.key[1], first.key[2], j - i);
    const FaceEntry& second = faces[i + 1];
    const std::size_t ca = static_cast<std::size_t>(first.owner / 8),
                      fa = static_cast<std::size_t>(first.owner % 8);
    if (second.owner < 0) {
      neighbour_[6 * ca + fa] = static_cast<std::int32_t>(second.owner);
    } else {
      const std::size_t cb = static_cast<std::size_t>(second.owner / 8),
                        fb = static_cast<std::size_t>(second.owner % 8);
      neighbour_[6 * ca + fa] = static_cast<std::int32_t>(cb);
      neighbour_face_[6 * ca + fa] = static_cast<std::int8_t>(fb);
      neighbour_[6 * cb + fb] = static_cast<std::int32_t>(ca);
      neighbour_face_[6 * cb + fb] = static_cast<std::int8_t>(fa);
    }
    i = j;
  }
  open_patch_.assign(patch_names_.size(), false);
  for (int p : open_patches)
    if (p >= 0 && p < static_cast<int>(open_patch_.size()))
      open_patch_[static_cast<std::size_t>(p)] = true;
  // No-slip nodes: those of wall faces (any patch but the open ones).
  wall_node_.assign(nodes_.size(), 0);
  for_each_boundary_face(mesh, [&](std::span<const NodeId> ids, std::int32_t patch) {
    if (!open_patch_[static_cast<std::size_t>(patch)])
      for (NodeId v : ids) wall_node_[static_cast<std::size_t>(v)] = 1;
  });
  wall_touching_.assign(n, 0);
  for (std::size_t cell = 0; cell < n; ++cell)
    for (NodeId v : cell_nodes(static_cast<int>(cell)))
      if (wall_node_[static_cast<std::size_t>(v)]) wall_touching_[cell] = 1;

  // Buckets about two cells wide, at most eight per cell.
  if (n == 0) fail("the mesh has no cells");
  Vec3 hi = nodes_[0];
  lo_ = nodes_[0];
  for (const Vec3& x : nodes_) {
    lo_ = lo_.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  double volume = 0.0;
  for (float s : size_) volume += static_cast<double>(s) * s * s;
  const Vec3 extent = (hi - lo_).cwiseMax(1e-12);
  bucket_ = std::max(2.0 * std::cbrt(volume / static_cast<double>(n)),
                     std::cbrt(extent.prod() / (8.0 * static_cast<double>(n))));
  for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, static_cast<int>(extent[a] / bucket_) + 1);
  const std::size_t buckets = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  auto range = [&](int cell, std::array<int, 3>& b0, std::array<int, 3>& b1) {
    Vec3 clo = nodes_[static_cast<std::size_t>(cell_nodes(cell)[0])], chi = clo;
    for (NodeId v : cell_nodes(cell)) {
      clo = clo.cwiseMin(nodes_[static_cast<std::size_t>(v)]);
      chi = chi.cwiseMax(nodes_[static_cast<std::size_t>(v)]);
    }
    for (int a = 0; a < 3; ++a) {
      b0[a] = std::clamp(static_cast<int>((clo[a] - lo_[a]) / bucket_), 0, dims_[a] - 1);
      b1[a] = std::clamp(static_cast<int>((chi[a] - lo_[a]) / bucket_), 0, dims_[a] - 1);
    }
  };
  bucket_start_.assign(buckets + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<std::uint32_t> fill;
    if (pass == 1) {
      for (std::size_t i = 0; i < buckets; ++i) bucket_start_[i + 1] += bucket_start_[i];
      bucket_cells_.resize(bucket_start_[buckets]);
      fill.assign(bucket_start_.begin(), bucket_start_.end() - 1);
    }
    for (std::size_t cell = 0; cell < n; ++cell) {
      std::array<int, 3> b0, b1;
      range(static_cast<int>(cell), b0, b1);
      for (int k = b0[2]; k <= b1[2]; ++k)
        for (int j = b0[1]; j <= b1[1]; ++j)
          for (int i = b0[0]; i <= b1[0]; ++i) {
            const std::size_t id =
                static_cast<std::size_t>(i) +
                static_cast<std::size_t>(dims_[0]) *
                    (static_cast<std::size_t>(j) + static_cast<std::size_t>(dims_[1]) * k);
            if (pass == 0)
              ++bucket_start_[id + 1];
            else
              bucket_cells_[fill[id]++] = static_cast<std::int32_t>(cell);
          }
    }
  }
}

bool MeshFlow::inside(int cell, const Vec3& x, double tolerance) const {
  for (const Plane& p : planes_of(cell))
    if (p.n().dot(x) - p.offset > tolerance) return false;
  return true;
}

Vec3 MeshFlow::cell_centre(int cell) const {
  Vec3 c = Vec3::Zero();
  for (NodeId v : cell_nodes(cell)) c += nodes_[static_cast<std::size_t>(v)];
  return c / static_cast<double>(cell_nodes(cell).size());
}

std::array<NodeId, 3> MeshFlow::triangle(int cell, const Plane& p) const {
  const auto ids = cell_nodes(cell);
  return face_triangle(
      ids, cell_faces(static_cast<int>(ids.size()))[static_cast<std::size_t>(p.face)], p.half);
}

double MeshFlow::wall_shift(int cell, int face, double radius) const {
  if (!(radius > 0.0)) return 0.0;
  const std::int32_t next =
      neighbour_[6 * static_cast<std::size_t>(cell) + static_cast<std::size_t>(face)];
  if (next >= 0 ||
      open_patch_[static_cast<std::size_t>(boundary_patch_[static_cast<std::size_t>(-1 - next)])])
    return 0.0;
  return radius;
}

bool MeshFlow::crosses_outwards(int cell, const Plane& p, const Vec3& a, const Vec3& d,
                                double& t) const {
  const auto tri = triangle(cell, p);
  const Vec3 p0 = nodes_[static_cast<std::size_t>(tri[0])] - a,
             p1 = nodes_[static_cast<std::size_t>(tri[1])] - a,
             p2 = nodes_[static_cast<std::size_t>(tri[2])] - a;
  const double s0 = d.dot(p0.cross(p1)), s1 = d.dot(p1.cross(p2)), s2 = d.dot(p2.cross(p0));
  if (!(s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0 && s0 + s1 + s2 > 0.0)) return false;
  t = p0.dot(p1.cross(p2)) / (s0 + s1 + s2);  // the products' sum is the normal's n·d > 0
  return true;
}

double MeshFlow::plane_crossing(int cell, const Plane& p, const Vec3& a, const Vec3& d,
                                double radius) const {
  const double nd = p.n().dot(d);
  if (!(nd > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (p.offset - wall_shift(cell, p.face, radius) - p.n().dot(a)) / nd;
}

const MeshFlow::Plane* MeshFlow::exit_plane(int cell, int entry, const Vec3& a, const Vec3& d,
                                            double t_now, double radius, double& t) const {
  // Crossings up to 10⁻⁶ cell sizes behind the point reached count: t_now may come from a plane
  // of single-precision normal, off by about 10⁻⁷ cell sizes.
  const double behind = 1e-6 * size_[static_cast<std::size_t>(cell)] / std::max(d.norm(), 1e-300);
  const bool convex = convex_[static_cast<std::size_t>(cell)] != 0;
  // The first plane the line crosses outwards: in a convex cell, the exit. Of the face entered
  // through, only a triangle the line crosses outwards (a fold of a non-convex cell) counts.
  const Plane* first = nullptr;
  double t_first = std::numeric_limits<double>::infinity();
  for (const Plane& p : planes_of(cell)) {
    double tf;
    if (p.face != entry)
      tf = plane_crossing(cell, p, a, d, radius);
    else if (convex || !crosses_outwards(cell, p, a, d, tf) || !(tf >= t_now - behind))
      continue;
    if (tf < t_first) {
      t_first = tf;
      first = &p;
    }
  }
  // The first plane is the exit in a convex cell with plane faces, beyond the segment, as a wall
  // plane shifted by the radius (met as a plane), or where its triangle is crossed; a bent
  // cell's first plane may be crossed outside its triangle.
  double t_check;
  if (convex || !first || t_first >= 1.0 || wall_shift(cell, first->face, radius) > 0.0 ||
      (crosses_outwards(cell, *first, a, d, t_check) && t_check >= t_now - behind)) {
    t = t_first;
    return first;
  }
  // The first triangle the line crosses outwards after t_now.
  const Plane* best = nullptr;
  t = std::numeric_limits<double>::infinity();
  for (const Plane& p : planes_of(cell)) {
    double tf;
    if (wall_shift(cell, p.face, radius) > 0.0)
      tf = plane_crossing(cell, p, a, d, radius);
    else if (!crosses_outwards(cell, p, a, d, tf) || !(tf >= t_now - behind))
      continue;
    if (tf < t) {
      t = tf;
      best = &p;
    }
  }
  if (best) return best;
  // Rounding left the line crossing no triangle outwards (or the segment starts outside the
  // cell): the first plane, as in a convex cell.
  t = t_first;
  return first;
}

Passage MeshFlow::pass(const Vec3& a, const Vec3& b, int& cell, double radius) const {
  const Vec3 d = b - a;
  Passage result;
  int entry = -1;
  double t_now = 0.0;
  for (int visit = 0; visit < kMaxWalk; ++visit) {
    ++result.cell_tests;
    double best_t;
    const Plane* best = exit_plane(cell, entry, a, d, t_now, radius, best_t);
    if (!best || best_t >= 1.0) return result;
    const std::size_t slot =
        6 * static_cast<std::size_t>(cell) + static_cast<std::size_t>(best->face);
    const std::int32_t next = neighbour_[slot];
    t_now = std::max(t_now, best_t);
    if (next < 0) {
      result.left = true;
      result.t = std::clamp(t_now, 0.0, 1.0);
      result.patch = boundary_patch_[static_cast<std::size_t>(-1 - next)];
      result.normal = best->n().normalized();
      return result;
    }
    entry = neighbour_face_[slot];
    cell = next;
  }
  // Along a face or an edge the walk can circle: the caller retries another segment.
  result.left = result.stuck = true;
  result.patch = -1;
  return result;
}

int MeshFlow::locate(const Vec3& x) const {
  std::array<int, 3> b{};
  for (int a = 0; a < 3; ++a) {
    const double s = (x[a] - lo_[a]) / bucket_;
    // A point on a face of the mesh's box may lie a rounding error outside it: the cells decide.
    if (!(s >= -1e-6) || s >= dims_[a]) return -1;
    b[a] = std::clamp(static_cast<int>(s), 0, dims_[a] - 1);
  }
  const std::size_t id =
      static_cast<std::size_t>(b[0]) +
      static_cast<std::size_t>(dims_[0]) *
          (static_cast<std::size_t>(b[1]) + static_cast<std::size_t>(dims_[1]) * b[2]);
  const std::uint32_t first = bucket_start_[id], last = bucket_start_[id + 1];
  for (std::uint32_t i = first; i < last; ++i) {
    const int c = bucket_cells_[i];
    if (inside(c, x, 1e-9 * size_[static_cast<std::size_t>(c)])) return c;
  }
  // The point lies in no candidate's planes (a face's fold): walk there from a candidate.
  for (std::uint32_t i = first; i < last; ++i) {
    int c = bucket_cells_[i];
    if (!pass(cell_centre(c), x, c, 0.0).left) return c;
  }
  return -1;
}

int MeshFlow::shape(int cell, const Vec3& x, std::array<double, 8>& value,
                    std::array<Vec3, 8>* gradient) const {
  const auto ids = cell_nodes(cell);
  const int n = static_cast<int>(ids.size());
  Eigen::Matrix<double, 8, 3> X8 = Eigen::Matrix<double, 8, 3>::Zero();
  for (int i = 0; i < n; ++i)
    X8.row(i) = nodes_[static_cast<std::size_t>(ids[static_cast<std::size_t>(i)])].transpose();
  auto store = [&](const auto& v, const auto& g) {
    for (int i = 0; i < n; ++i) {
      value[static_cast<std::size_t>(i)] = v[i];
      if (gradient) (*gradient)[static_cast<std::size_t>(i)] = g.row(i).transpose();
    }
  };
  const bool affine = affine_[static_cast<std::size_t>(cell)] != 0;
  if (n == 4) {
    Eigen::Matrix3d A;
    for (int k = 0; k < 3; ++k) A.col(k) = (X8.row(k + 1) - X8.row(0)).transpose();
    const Eigen::Matrix3d inv = A.inverse();  // rows: ∇λ₁, ∇λ₂, ∇λ₃
    const Vec3 l = inv * (x - X8.row(0).transpose());
    Eigen::Matrix<double, 4, 3> g;
    g.row(0) = -(inv.row(0) + inv.row(1) + inv.row(2));
    g.bottomRows<3>() = inv;
    store(Eigen::Vector4d(1.0 - l.sum(), l[0], l[1], l[2]), g);
  } else if (n == 5) {
    Eigen::Matrix<double, 5, 1> v;
    Eigen::Matrix<double, 5, 3> g;
    inverse_map<fem::Pyr5, 5>(Eigen::Matrix<double, 5, 3>(X8.topRows<5>()), x, Vec3(0.0, 0.0, 0.25),
                              false, v, gradient ? &g : nullptr);
    store(v, g);
  } else {
    Eigen::Matrix<double, 8, 1> v;
    Eigen::Matrix<double, 8, 3> g;
    inverse_map<fem::Hex8, 8>(X8, x, Vec3::Zero(), affine, v, gradient ? &g : nullptr);
    store(v, g);
  }
  return n;
}

Vec3 MeshFlow::velocity_in_cell(int cell, const Vec3& x, bool wall_law) const {
  std::array<double, 8> value;
  std::array<Vec3, 8> gradient;
  const bool near_wall = wall_law && wall_touching_[static_cast<std::size_t>(cell)];
  const int n = shape(cell, x, value, near_wall ? &gradient : nullptr);
  const auto ids = cell_nodes(cell);
  Vec3 u = Vec3::Zero(), g = Vec3::Zero();
  double w = 0.0;
  for (int i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(ids[static_cast<std::size_t>(i)]);
    u += value[static_cast<std::size_t>(i)] * velocity_[v];
    if (near_wall && !wall_node_[v]) {
      w += value[static_cast<std::size_t>(i)];
      g += gradient[static_cast<std::size_t>(i)];
    }
  }
  // Near the wall: w, the weight of the nodes off the wall, grows from 0 on the wall's nodes
  // like the distance from them; the component along ∇w is scaled by w (see mesh_flow.h).
  if (!near_wall || !(g.squaredNorm() > 0.0)) return u;
  const Vec3 e = g.normalized();
  return u - (1.0 - std::clamp(w, 0.0, 1.0)) * u.dot(e) * e;
}

Vec3 MeshFlow::velocity(const Vec3& from, int& cell, const Vec3& x) const {
  pass(from, x, cell, 0.0);
  return velocity_in_cell(cell, x);
}

}  // namespace naris::particles
