#include "mesh/image/nasal_airway.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "core/error.h"
#include "mesh/image/distance_transform.h"
#include "mesh/image/segment.h"

namespace naris {
namespace {

constexpr double kLumenDepth = 1.5;          // mm
constexpr double kPlaceDynamics = 1.0;       // mm: a wide place stands this far above its saddle
constexpr double kPharynxDepth = 5.0;        // mm: the nasopharynx is at least this wide ...
constexpr double kPharynxOffMidline = 15.0;  // mm: ... and this near the midline
constexpr double kChoanaSearch = 10.0;       // mm behind the nares: where the choana search starts
constexpr double kBehindChoanae = 5.0;       // mm: both cavities end this far behind the choanae

using Mask = std::vector<std::uint8_t>;

// Lumen lies at least this far from tissue (mm): kLumenDepth, or a voxel on a coarse grid
// (thin-slice CTs resolve the skin's partial-volume rim in more voxels, not more millimetres).
double lumen_depth(const ImageFrame& frame) {
  return std::max(kLumenDepth, frame.spacing.maxCoeff());
}

// Index arithmetic and 6-neighbourhoods on one grid.
struct VoxelGrid {
  std::array<int, 3> n;
  std::array<std::size_t, 3> stride;
  explicit VoxelGrid(const ImageFrame& f)
      : n(f.dims),
        stride{1, static_cast<std::size_t>(f.dims[0]),
               static_cast<std::size_t>(f.dims[0]) * static_cast<std::size_t>(f.dims[1])} {}
  std::size_t size() const { return stride[2] * static_cast<std::size_t>(n[2]); }
  int coord(std::size_t q, int axis) const {
    return static_cast<int>(q / stride[axis] % static_cast<std::size_t>(n[axis]));
  }
  bool on_border(std::size_t q) const {
    for (int a = 0; a < 3; ++a)
      if (coord(q, a) == 0 || coord(q, a) + 1 == n[a]) return true;
    return false;
  }
  Eigen::Vector3d ijk(std::size_t q) const {
    return Eigen::Vector3d(coord(q, 0), coord(q, 1), coord(q, 2));
  }
  template <class F>
  void neighbours(std::size_t q, F&& f) const {
    for (int a = 0; a < 3; ++a) {
      const int c = coord(q, a);
      if (c > 0) f(q - stride[a], a, -1);
      if (c + 1 < n[a]) f(q + stride[a], a, +1);
    }
  }
};

// The 6-connected region of `inside` reached from the seeds.
template <class Inside>
Mask flood(const VoxelGrid& g, const std::vector<std::size_t>& seeds, Inside&& inside) {
  Mask out(g.size(), 0);
  std::vector<std::size_t> stack;
  for (std::size_t s : seeds)
    if (!out[s] && inside(s)) out[s] = 1, stack.push_back(s);
  while (!stack.empty()) {
    const std::size_t q = stack.back();
    stack.pop_back();
    g.neighbours(q, [&](std::size_t r, int, int) {
      if (!out[r] && inside(r)) out[r] = 1, stack.push_back(r);
    });
  }
  return out;
}

// The image axes closest to the patient's left (x), posterior (y) and superior (z) in LPS, with
// the sign of each along its axis.
struct PatientAxes {
  std::array<int, 3> axis{0, 1, 2};
  std::array<int, 3> sign{1, 1, 1};
};
PatientAxes patient_axes(const ImageFrame& f) {
  PatientAxes p;
  for (int d = 0; d < 3; ++d) {
    int best = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(f.direction(d, a)) > std::abs(f.direction(d, best))) best = a;
    p.axis[d] = best;
    p.sign[d] = f.direction(d, best) < 0 ? -1 : 1;
  }
  if (p.axis[0] == p.axis[1] || p.axis[1] == p.axis[2] || p.axis[0] == p.axis[2])
    fail("the image is oblique to the patient's axes by about 45°: resample it first");
  return p;
}

// De-identification masks (blanked eyes, faces): regions of exactly the image's minimum with
// hard edges, which no scanner makes (real air blurs into tissue over a voxel). In each slice
// across `axis`, a 4-connected region of the minimum that keeps off the slice's border and whose
// edge is mostly denser than −200 HU is tissue. Returns the count of voxels so marked in `tissue`.
std::size_t mark_masked_regions(const Volume<float>& ct, const VoxelGrid& g, int axis,
                                Mask& tissue) {
  const float lowest = *std::min_element(ct.values.begin(), ct.values.end());
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  Mask seen(g.size(), 0);
  std::vector<std::size_t> region, stack;
  std::size_t marked = 0;
  for (std::size_t s = 0; s < g.size(); ++s) {
    if (seen[s] || ct.values[s] != lowest) continue;
    region.clear();
    stack.assign(1, s);
    seen[s] = 1;
    std::size_t hard = 0, soft = 0;
    bool edge = false;
    while (!stack.empty()) {
      const std::size_t q = stack.back();
      stack.pop_back();
      region.push_back(q);
      for (int a : {a1, a2}) {
        const int c = g.coord(q, a);
        for (int d : {-1, 1}) {
          if (c + d < 0 || c + d >= g.n[a]) {
            edge = true;  // the scan's own border: room air or outside the field of view
            continue;
          }
          const std::size_t r = d < 0 ? q - g.stride[a] : q + g.stride[a];
          if (ct.values[r] == lowest) {
            if (!seen[r]) seen[r] = 1, stack.push_back(r);
          } else {
            ++(ct.values[r] > -200.0f ? hard : soft);
          }
        }
      }
    }
    if (!edge && hard > soft && region.size() >= 16) {
      for (std::size_t q : region) tissue[q] = 1;
      marked += region.size();
    }
  }
  return marked;
}

// The room air: what balls of `radius` reach from the scan's open sides without entering the
// body closed at that radius (a morphological closing of the tissue: the nostrils, narrower than
// the balls, are closed). Of the regions that touch the volume's border on the rim of one of its
// faces, the largest is the room; an airway cut by the border (the nasopharynx at the bottom of
// the scan) is enclosed by tissue on that face and is not a room seed.
Mask room_air(const ImageFrame& frame, const VoxelGrid& g, const Mask& tissue, double radius,
              int threads) {
  const std::size_t n = g.size();
  const double r2 = radius * radius;
  std::vector<float> d2 = squared_distance(frame, tissue, OutsideIs::nothing, threads);
  Mask far(n);
  for (std::size_t q = 0; q < n; ++q) far[q] = d2[q] > r2;
  d2 = squared_distance(frame, far, OutsideIs::nothing, threads);
  Mask open(n);  // outside the closed body
  for (std::size_t q = 0; q < n; ++q) open[q] = d2[q] <= r2;
  d2 = {};
  // Rim seeds: on each face of the box, the open voxels connected within the face to its edge.
  std::vector<std::size_t> seeds;
  for (int axis = 0; axis < 3; ++axis)
    for (int end : {0, g.n[axis] - 1}) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      auto at = [&](int u, int v) {
        return g.stride[axis] * static_cast<std::size_t>(end) +
               g.stride[a1] * static_cast<std::size_t>(u) +
               g.stride[a2] * static_cast<std::size_t>(v);
      };
      Mask mark(static_cast<std::size_t>(g.n[a1]) * static_cast<std::size_t>(g.n[a2]), 0);
      std::vector<std::pair<int, int>> stack;
      auto push = [&](int u, int v) {
        if (u < 0 || v < 0 || u >= g.n[a1] || v >= g.n[a2]) return;
        const std::size_t m = static_cast<std::size_t>(u) + static_cast<std::size_t>(g.n[a1]) * v;
        if (mark[m] || !open[at(u, v)]) return;
        mark[m] = 1;
        stack.emplace_back(u, v);
      };
      for (int u = 0; u < g.n[a1]; ++u) push(u, 0), push(u, g.n[a2] - 1);
      for (int v = 0; v < g.n[a2]; ++v) push(0, v), push(g.n[a1] - 1, v);
      while (!stack.empty()) {
        const auto [u, v] = stack.back();
        stack.pop_back();
        seeds.push_back(at(u, v));
        push(u + 1, v), push(u - 1, v), push(u, v + 1), push(u, v - 1);
      }
    }
  // The largest 6-connected open region holding a seed.
  Mask seen(n, 0);
  std::size_t best = 0, best_seed = 0;
  std::vector<std::size_t> stack;
  for (std::size_t s : seeds) {
    if (seen[s]) continue;
    std::size_t size = 0;
    stack.assign(1, s);
    seen[s] = 1;
    while (!stack.empty()) {
      const std::size_t q = stack.back();
      stack.pop_back();
      ++size;
      g.neighbours(q, [&](std::size_t r, int, int) {
        if (!seen[r] && open[r]) seen[r] = 1, stack.push_back(r);
      });
    }
    if (size > best) best = size, best_seed = s;
  }
  return flood(g, {best_seed}, [&](std::size_t q) { return open[q] != 0; });
}

// A naris candidate: a 26-connected set of inner air voxels that face the room air.
struct NarisVoxels {
  Naris naris;
  std::vector<std::size_t> voxels;
  std::vector<Eigen::Vector3d> faces;  // centres of the voxel faces shared with the room air
};

// Openings of the lumen (voxels at least `min_depth` from tissue, not the partial-volume rim along
// the skin) to the room air.
std::vector<NarisVoxels> find_nares(const ImageFrame& frame, const VoxelGrid& g, const Mask& inner,
                                    const Mask& room, const std::vector<float>& depth,
                                    double min_depth) {
  const std::size_t n = g.size();
  Mask faces(n, 0);
  for (std::size_t q = 0; q < n; ++q) {
    if (!inner[q] || depth[q] < min_depth) continue;
    g.neighbours(q, [&](std::size_t r, int, int) { faces[q] |= room[r]; });
  }
  const Eigen::Matrix3d m = frame.index_to_physical();
  const Eigen::Vector3d& s = frame.spacing;
  const std::array<double, 3> face_area{s[1] * s[2], s[0] * s[2], s[0] * s[1]};
  std::vector<NarisVoxels> out;
  Mask seen(n, 0);
  for (std::size_t s0 = 0; s0 < n; ++s0) {
    if (!faces[s0] || seen[s0]) continue;
    NarisVoxels c;
    std::vector<std::size_t> stack{s0};
    seen[s0] = 1;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
    while (!stack.empty()) {
      const std::size_t q = stack.back();
      stack.pop_back();
      c.voxels.push_back(q);
      const Eigen::Vector3d ijk = g.ijk(q);
      g.neighbours(q, [&](std::size_t r, int axis, int dir) {
        if (!room[r]) return;
        Eigen::Vector3d step = Eigen::Vector3d::Zero();
        step[axis] = dir;
        const Eigen::Vector3d out_dir = (m * step).normalized();
        c.naris.area += face_area[axis];
        c.faces.push_back(frame.physical(ijk + 0.5 * step));
        weighted += face_area[axis] * c.faces.back();
        normal += face_area[axis] * out_dir;
      });
      // 26-neighbours among the facing voxels.
      for (int dk = -1; dk <= 1; ++dk)
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const int i = static_cast<int>(ijk[0]) + di, j = static_cast<int>(ijk[1]) + dj,
                      k = static_cast<int>(ijk[2]) + dk;
            if (i < 0 || j < 0 || k < 0 || i >= g.n[0] || j >= g.n[1] || k >= g.n[2]) continue;
            const std::size_t r = frame.index(i, j, k);
            if (faces[r] && !seen[r]) seen[r] = 1, stack.push_back(r);
          }
    }
    c.naris.centre = weighted / c.naris.area;
    c.naris.normal = normal.norm() > 0 ? normal.normalized() : Eigen::Vector3d::Zero();
    out.push_back(std::move(c));
  }
  return out;
}

// The distinct wide places of the airway: regional maxima of the distance to tissue whose
// dynamics (how far the distance falls on the way to a wider place) is at least `h`. Found by
// merging 6-connected components in decreasing distance (a union–find over the airway).
std::vector<std::size_t> wide_places(const VoxelGrid& g, const Mask& airway,
                                     const std::vector<float>& depth, double h) {
  std::vector<std::size_t> order;
  for (std::size_t q = 0; q < g.size(); ++q)
    if (airway[q]) order.push_back(q);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return depth[a] > depth[b]; });
  std::vector<std::int32_t> id(g.size(), -1);
  std::vector<std::int32_t> parent(order.size());
  std::vector<std::size_t> peak(order.size());  // per root: its deepest voxel
  auto root = [&](std::int32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::vector<std::size_t> places;
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const std::size_t q = order[rank];
    auto self = static_cast<std::int32_t>(rank);
    id[q] = self;
    parent[self] = self;
    peak[self] = q;
    g.neighbours(q, [&](std::size_t r, int, int) {
      if (id[r] < 0) return;
      std::int32_t a = root(self), b = root(id[r]);
      if (a == b) return;
      // The lower peak dies here; it was a place of its own if it stood h above this level.
      if (depth[peak[a]] > depth[peak[b]]) std::swap(a, b);
      if (depth[peak[a]] - depth[q] >= h) places.push_back(peak[a]);
      parent[a] = b;
    });
  }
  // The deepest place of each remaining component never died.
  for (std::size_t rank = 0; rank < order.size(); ++rank)
    if (parent[rank] == static_cast<std::int32_t>(rank)) places.push_back(peak[rank]);
  return places;
}

// Seeded watershed on the distance to tissue: every airway voxel gets the widest bottleneck of a
// path to it from the seeds (the largest, over paths, of the smallest distance along the path)
// and the label of the seed it is so reached from (ties: the first reached).
struct WidestPaths {
  std::vector<float> bottleneck;
  Mask label;
};
WidestPaths widest_paths(const VoxelGrid& g, const Mask& airway, const std::vector<float>& depth,
                         const std::vector<std::pair<std::size_t, std::uint8_t>>& seeds) {
  WidestPaths w{std::vector<float>(g.size(), -1.0f), Mask(g.size(), 0)};
  std::priority_queue<std::pair<float, std::size_t>> queue;
  for (const auto& [s, l] : seeds)
    w.label[s] = l, w.bottleneck[s] = depth[s], queue.emplace(depth[s], s);
  while (!queue.empty()) {
    const auto [value, q] = queue.top();
    queue.pop();
    if (value < w.bottleneck[q]) continue;
    g.neighbours(q, [&](std::size_t r, int, int) {
      if (!airway[r]) return;
      const float v = std::min(value, depth[r]);
      if (v > w.bottleneck[r]) w.bottleneck[r] = v, w.label[r] = w.label[q], queue.emplace(v, r);
    });
  }
  return w;
}

// The two sides: each airway voxel goes to the naris it is nearest to along the airway (a
// geodesic Voronoi split: the fronts meet at a gap in a thin septum and in the middle of the
// nasopharynx). The choana is the last coronal slice, from the front, before the split runs
// through open air (depth ≥ `open_depth` mm from the walls) rather than through a septum,
// searched from 10 mm behind the nares.
struct SideSplit {
  Mask side;  // 1 right, 2 left
  std::optional<int> choana;
};
SideSplit split_sides(const ImageFrame& frame, const VoxelGrid& g, const Mask& nasal,
                      const std::vector<float>& depth, const std::vector<std::size_t>& right,
                      const std::vector<std::size_t>& left, int ap, int ap_sign,
                      double open_depth) {
  SideSplit s;
  s.side.assign(g.size(), 0);
  std::vector<float> dist(g.size(), std::numeric_limits<float>::infinity());
  using Item = std::pair<float, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::size_t q : right) dist[q] = 0.0f, s.side[q] = 1, queue.emplace(0.0f, q);
  for (std::size_t q : left) dist[q] = 0.0f, s.side[q] = 2, queue.emplace(0.0f, q);
  while (!queue.empty()) {
    const auto [d, q] = queue.top();
    queue.pop();
    if (d > dist[q]) continue;
    g.neighbours(q, [&](std::size_t r, int axis, int) {
      if (!nasal[r]) return;
      const float v = d + static_cast<float>(frame.spacing[axis]);
      if (v < dist[r]) dist[r] = v, s.side[r] = s.side[q], queue.emplace(v, r);
    });
  }
  // Per coronal slice: does the boundary between the sides pass through open air?
  std::vector<int> open_pairs(static_cast<std::size_t>(g.n[ap]), 0);
  for (std::size_t q = 0; q < g.size(); ++q) {
    if (s.side[q] != 1) continue;
    g.neighbours(q, [&](std::size_t r, int axis, int) {
      if (axis != ap && s.side[r] == 2 && std::min(depth[q], depth[r]) >= open_depth)
        ++open_pairs[static_cast<std::size_t>(g.coord(q, ap))];
    });
  }
  // From 10 mm behind the nares (their vestibules may meet under the columella, in front).
  int start = 0;
  for (const auto* seeds : {&right, &left})
    for (std::size_t q : *seeds) {
      const int c = g.coord(q, ap);
      start = std::max(start, ap_sign > 0 ? c : g.n[ap] - 1 - c);
    }
  start += static_cast<int>(std::ceil(kChoanaSearch / frame.spacing[ap]));
  for (int t = start; t < g.n[ap]; ++t) {
    const int slice = ap_sign > 0 ? t : g.n[ap] - 1 - t;
    if (open_pairs[static_cast<std::size_t>(slice)] >= 3) {
      s.choana = slice - ap_sign;
      break;
    }
  }
  return s;
}

std::string plane_text(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  return fmt::format("p={:.3f},{:.3f},{:.3f};n={:.5f},{:.5f},{:.5f}", p[0], p[1], p[2], n[0], n[1],
                     n[2]);
}

// The nares: the widest downward opening of the lumen to the room air on each side of the
// airway's midline. Owns the candidates the pointers point into.
struct Nares {
  std::vector<NarisVoxels> candidates;
  const NarisVoxels* right = nullptr;
  const NarisVoxels* left = nullptr;
  double mid_x = 0.0;               // the midline between them (x, LPS: left +)
  std::vector<std::size_t> voxels;  // of both
  double level = 0.0;               // their area-weighted height (z)
  // Those the airway of `side` is entered by.
  std::vector<const NarisVoxels*> of(NasalSide side) const {
    std::vector<const NarisVoxels*> out;
    for (const NarisVoxels* c : {right, left})
      if (c && (side == NasalSide::both || c == (side == NasalSide::right ? right : left)))
        out.push_back(c);
    return out;
  }
};

Nares choose_nares(const ImageFrame& frame, const VoxelGrid& g, const Mask& inner, const Mask& room,
                   const std::vector<float>& depth, NasalSide side) {
  const double min_opening = lumen_depth(frame);
  Nares nares;
  nares.candidates = find_nares(frame, g, inner, room, depth, min_opening);
  // The nostrils open downwards (and forwards): an opening that faces more to the front or the
  // side than to the feet is the mouth, a de-identification mask or the skin, not a naris.
  std::erase_if(nares.candidates, [&](const NarisVoxels& c) {
    return c.naris.area < 4.0 * min_opening * min_opening || c.naris.normal[2] > -0.5;
  });
  if (nares.candidates.empty())
    fail(
        "no naris found: no air inside the body opens downwards to the room air wider than "
        "{:.1f} mm (is the nose inside the scan?)",
        min_opening);
  std::sort(nares.candidates.begin(), nares.candidates.end(),
            [](const auto& a, const auto& b) { return a.naris.area > b.naris.area; });
  std::vector<std::size_t> all;
  for (const auto& c : nares.candidates) all.insert(all.end(), c.voxels.begin(), c.voxels.end());
  const Mask reached = flood(g, all, [&](std::size_t q) { return inner[q] != 0; });
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t count = 0;
  for (std::size_t q = 0; q < g.size(); ++q)
    if (reached[q]) sum += g.ijk(q), ++count;
  nares.mid_x = frame.physical(sum / static_cast<double>(count))[0];
  for (const auto& c : nares.candidates) {
    const NarisVoxels*& slot = c.naris.centre[0] < nares.mid_x ? nares.right : nares.left;
    if (!slot) slot = &c;
  }
  if (nares.right && nares.left)
    nares.mid_x = 0.5 * (nares.right->naris.centre[0] + nares.left->naris.centre[0]);
  if (side == NasalSide::right && !nares.right)
    fail("no right naris found (the openings found lie left of the midline x = {:.1f} mm)",
         nares.mid_x);
  if (side == NasalSide::left && !nares.left)
    fail("no left naris found (the openings found lie right of the midline x = {:.1f} mm)",
         nares.mid_x);
  double area = 0.0;
  for (const NarisVoxels* c : {nares.right, nares.left})
    if (c) {
      nares.voxels.insert(nares.voxels.end(), c->voxels.begin(), c->voxels.end());
      nares.level += c->naris.area * c->naris.centre[2];
      area += c->naris.area;
    }
  nares.level /= area;
  return nares;
}

// Sinuses: wide places reached only through a way in narrower by the margin, except the
// nasopharynx (the lowest wide place near the midline, below the airway's mean level); high
// above the nares only ethmoid (and frontal, sphenoid) cells are wide, and any narrowing on
// their way in makes them sinuses. Returns each airway voxel's label: 1 nasal, 2 sinus.
Mask separate_sinuses(const ImageFrame& frame, const VoxelGrid& g, const Mask& airway,
                      const std::vector<float>& depth, const Nares& nares,
                      const NasalAirwayOptions& o, std::size_t& sinuses) {
  std::vector<std::pair<std::size_t, std::uint8_t>> seeds;
  for (std::size_t q : nares.voxels) seeds.emplace_back(q, 1);
  const std::vector<float> way_in = widest_paths(g, airway, depth, seeds).bottleneck;
  const std::vector<std::size_t> places = wide_places(g, airway, depth, kPlaceDynamics);
  auto position = [&](std::size_t q) { return frame.physical(g.ijk(q)); };
  double mean_level = 0.0;
  std::size_t count = 0;
  for (std::size_t q = 0; q < g.size(); ++q)
    if (airway[q]) mean_level += position(q)[2], ++count;
  mean_level /= static_cast<double>(count);
  std::optional<std::size_t> pharynx;
  for (std::size_t p : places) {
    const Eigen::Vector3d x = position(p);
    if (depth[p] < kPharynxDepth || std::abs(x[0] - nares.mid_x) > kPharynxOffMidline ||
        x[2] > mean_level)
      continue;
    if (!pharynx || x[2] < position(*pharynx)[2]) pharynx = p;
  }
  sinuses = 0;
  for (std::size_t p : places) {
    const double margin =
        position(p)[2] - nares.level > o.ethmoid_height ? o.ethmoid_margin : o.sinus_margin;
    const bool sinus = p != pharynx && depth[p] - way_in[p] >= margin;
    seeds.emplace_back(p, sinus ? 2 : 1);
    sinuses += sinus;
  }
  return widest_paths(g, airway, depth, seeds).label;
}

// The side or sides asked for, with the choana (out.choana) and the outlet plane (out.outlet).
Mask select_side(const ImageFrame& frame, const VoxelGrid& g, const Mask& nasal,
                 const std::vector<float>& depth, const Nares& nares, const NasalAirwayOptions& o,
                 const PatientAxes& axes, NasalAirway& out) {
  const int ap = axes.axis[1], ap_sign = axes.sign[1];
  SideSplit split;
  if (nares.right && nares.left) {
    split = split_sides(frame, g, nasal, depth, nares.right->voxels, nares.left->voxels, ap,
                        ap_sign, lumen_depth(frame));
    out.choana = split.choana;
  }
  auto behind = [&](std::size_t q, int slice) {  // strictly posterior of `slice`
    return ap_sign > 0 ? g.coord(q, ap) > slice : g.coord(q, ap) < slice;
  };
  const char axis_letter = static_cast<char>('i' + ap);
  if (o.side == NasalSide::both) {
    if (o.keep_nasopharynx || !out.choana) return nasal;
    // Both cavities end a little behind the choanae, where they have joined.
    const int extra = static_cast<int>(std::ceil(kBehindChoanae / frame.spacing[ap]));
    const int cut = std::clamp(*out.choana + ap_sign * extra, 0, g.n[ap] - 1);
    out.outlet = fmt::format("{}={}", axis_letter, cut);
    return flood(g, nares.voxels, [&](std::size_t q) { return nasal[q] && !behind(q, cut); });
  }
  if (nares.right && nares.left && !out.choana)
    fail(
        "the {} side cannot be separated: no choana found (the boundary between the sides never "
        "runs through open air: is the nasopharynx in the scan?)",
        nasal_side_name(o.side));
  const std::uint8_t my_side = o.side == NasalSide::right ? 1 : 2;
  auto keep = [&](std::size_t q) {
    if (!nasal[q]) return false;
    if (out.choana && behind(q, *out.choana)) return o.keep_nasopharynx;
    return split.side.empty() || split.side[q] == my_side;
  };
  if (out.choana && !o.keep_nasopharynx)
    out.outlet = fmt::format("{}={}", axis_letter, *out.choana);
  return flood(g, nares.of(o.side).front()->voxels, keep);
}

// The wall's partial-volume layer: voxels between the threshold and `wall_level` that touch the
// airway and no other air (a sinus, the other side, the room) join it, unless they are a
// one-voxel wall with airway on both sides (a septal gap, a turbinate's edge would open). The
// threshold decides what connects to what; this moves the wall out by a voxel, where the
// experts draw it. Nothing on the scan's border (closed by wall) or past the airway's A-P cuts.
std::size_t add_wall_layer(const Volume<float>& ct, const VoxelGrid& g, const Mask& tissue,
                           float wall_level, int ap, Mask& airway) {
  int lo = g.n[ap], hi = -1;
  for (std::size_t q = 0; q < g.size(); ++q)
    if (airway[q]) lo = std::min(lo, g.coord(q, ap)), hi = std::max(hi, g.coord(q, ap));
  std::vector<std::size_t> layer;
  for (std::size_t q = 0; q < g.size(); ++q) {
    // Tissue below the wall level; masked voxels are tissue but at the image's minimum.
    if (airway[q] || !tissue[q] || !(ct.values[q] < wall_level)) continue;
    if (g.coord(q, ap) < lo || g.coord(q, ap) > hi) continue;
    if (g.on_border(q)) continue;
    bool touches = false, other_air = false, between = false;
    std::array<int, 3> sides{};  // per axis: airway on the -1 side (1), the +1 side (2)
    g.neighbours(q, [&](std::size_t r, int a, int d) {
      if (airway[r]) touches = true, sides[a] |= d < 0 ? 1 : 2;
      other_air |= !tissue[r] && !airway[r];
    });
    for (int s : sides) between |= s == 3;
    if (touches && !other_air && !between) layer.push_back(q);
  }
  for (std::size_t q : layer) airway[q] = 1;
  return layer.size();
}

// The inlet: the area-weighted plane of the openings. They are caps that bulge into the
// vestibule where the room air reaches in (a wide nostril lets the closing's balls in), so the
// plane goes in past the deepest tenth of their faces by kLumenDepth, where the vestibule is one
// whole section.
std::string inlet_plane(const std::vector<const NarisVoxels*>& nares) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
  double area = 0.0;
  for (const NarisVoxels* c : nares) {
    centre += c->naris.area * c->naris.centre;
    normal += c->naris.area * c->naris.normal;
    area += c->naris.area;
  }
  centre /= area;
  normal.normalize();
  std::vector<double> depths;
  for (const NarisVoxels* c : nares)
    for (const Eigen::Vector3d& f : c->faces) depths.push_back((f - centre).dot(normal));
  const auto tenth = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 10);
  std::nth_element(depths.begin(), tenth, depths.end());
  return plane_text(centre + (*tenth - kLumenDepth) * normal, normal);
}

}  // namespace

NasalSide parse_nasal_side(const std::string& text) {
  if (text == "right") return NasalSide::right;
  if (text == "left") return NasalSide::left;
  if (text == "both") return NasalSide::both;
  fail("side '{}' is not right, left or both", text);
}

const char* nasal_side_name(NasalSide side) {
  constexpr const char* names[] = {"right", "left", "both"};
  return names[static_cast<int>(side)];
}

NasalAirway segment_nasal_airway(const Volume<float>& ct, const NasalAirwayOptions& o) {
  if (!(o.closing_radius > 0.0)) fail("the closing radius must be positive");
  if (!(o.sinus_margin > 0.0) || !(o.ethmoid_margin > 0.0))
    fail("the sinus margins must be positive");
  const ImageFrame& frame = ct.frame;
  const VoxelGrid g(frame);
  const std::size_t n = g.size();
  const double voxel_ml = frame.spacing.prod() / 1000.0;
  const PatientAxes axes = patient_axes(frame);
  NasalAirway out;
  if (o.threshold) {
    out.threshold = out.wall_level = *o.threshold;
  } else {
    // Partial-volume voxels of the narrow meatuses still pass half-way from the histogram's
    // air–tissue valley to water (0 HU); the wall is drawn 60 % of the way.
    const double valley = air_threshold(ct);
    out.threshold = 0.5 * valley;
    out.wall_level = 0.4 * valley;
  }
  out.ap_axis = axes.axis[1];

  Mask tissue(n);
  for (std::size_t q = 0; q < n; ++q) tissue[q] = !(ct.values[q] < out.threshold);
  out.masked_voxels = mark_masked_regions(ct, g, axes.axis[2], tissue);
  const Mask room = room_air(frame, g, tissue, o.closing_radius, o.threads);
  Mask inner(n);
  std::size_t inner_count = 0, room_count = 0;
  for (std::size_t q = 0; q < n; ++q) {
    inner[q] = !tissue[q] && !room[q];
    inner_count += inner[q];
    room_count += room[q];
  }
  out.room_ml = static_cast<double>(room_count) * voxel_ml;
  if (inner_count == 0)
    fail("no air inside the body below {:.0f} HU: is this a head CT with its nasal airway?",
         out.threshold);
  std::vector<float> depth = squared_distance(frame, tissue, OutsideIs::nothing, o.threads);
  for (float& d : depth) d = std::sqrt(d);

  const Nares nares = choose_nares(frame, g, inner, room, depth, o.side);
  const Mask airway = flood(g, nares.voxels, [&](std::size_t q) { return inner[q] != 0; });
  const Mask label = separate_sinuses(frame, g, airway, depth, nares, o, out.sinuses);
  Mask nasal(n);
  std::size_t sinus_count = 0;
  for (std::size_t q = 0; q < n; ++q) {
    nasal[q] = label[q] == 1;
    sinus_count += label[q] == 2;
  }
  out.sinus_ml = static_cast<double>(sinus_count) * voxel_ml;

  Mask result = select_side(frame, g, nasal, depth, nares, o, axes, out);
  // Air cut by the scan's border is closed there by a wall: no stray open patch for the mesher.
  for (std::size_t q = 0; q < n; ++q)
    if (g.on_border(q)) result[q] = 0;
  out.wall_layer_ml =
      static_cast<double>(
          add_wall_layer(ct, g, tissue, static_cast<float>(out.wall_level), axes.axis[1], result)) *
      voxel_ml;

  for (const NarisVoxels* c : nares.of(o.side)) {
    out.nares.push_back(c->naris);
    out.nares.back().right = c == nares.right;
  }
  out.inlet = inlet_plane(nares.of(o.side));

  std::size_t kept = 0;
  for (auto v : result) kept += v;
  out.volume_ml = static_cast<double>(kept) * voxel_ml;
  out.regions.frame = frame;
  out.regions.values.resize(n);
  for (std::size_t q = 0; q < n; ++q) {
    AirwayRegion r = AirwayRegion::tissue;
    if (result[q])
      r = AirwayRegion::airway;
    else if (label[q] == 2)
      r = AirwayRegion::sinus;
    else if (nasal[q])
      r = AirwayRegion::excluded;
    else if (room[q])
      r = AirwayRegion::room;
    else if (inner[q])
      r = AirwayRegion::enclosed;
    else if (tissue[q] && ct.values[q] < out.threshold)
      r = AirwayRegion::masked;
    out.regions.values[q] = static_cast<std::uint8_t>(r);
  }
  out.mask.frame = frame;
  out.mask.values = std::move(result);
  return out;
}

}  // namespace naris
