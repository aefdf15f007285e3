#include "mesh/quality/quality.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>

#include "core/error.h"
#include "core/parallel.h"

namespace naris {
namespace {

using Vec = Eigen::Vector3d;
constexpr double kDeg = 180.0 / std::numbers::pi;

// Cell shapes in VTK order: outward faces (the shared tables), the pairs of faces that meet at
// an edge, and for each corner three neighbours that form a right-handed frame in a valid cell.
struct Shape {
  std::span<const CellFace> faces;
  std::vector<std::array<int, 2>> adjacent_faces;
  std::vector<std::array<int, 4>> corners;  // vertex, then its three neighbours
  double jacobian_scale;                    // makes the ideal cell's corners 1
};

std::vector<std::array<int, 2>> adjacent_faces(std::span<const CellFace> faces) {
  auto has = [](const CellFace& f, int node) {
    return std::find(f.v.begin(), f.v.begin() + f.size, node) != f.v.begin() + f.size;
  };
  std::vector<std::array<int, 2>> pairs;
  for (int f = 0; f < static_cast<int>(faces.size()); ++f)
    for (int g = f + 1; g < static_cast<int>(faces.size()); ++g) {
      int shared = 0;
      for (int k = 0; k < faces[f].size; ++k) shared += has(faces[g], faces[f].v[k]);
      if (shared == 2) pairs.push_back({f, g});
    }
  return pairs;
}

const Shape kTet{kTetFaces,
                 adjacent_faces(kTetFaces),
                 {kTetCorners.begin(), kTetCorners.end()},
                 std::numbers::sqrt2};
const Shape kPyramid{kPyramidFaces,
                     adjacent_faces(kPyramidFaces),
                     {kPyramidCorners.begin(), kPyramidCorners.end()},
                     std::numbers::sqrt2};
const Shape kHex{
    kHexFaces, adjacent_faces(kHexFaces), {kHexCorners.begin(), kHexCorners.end()}, 1.0};

Vec face_normal(const CellFace& f, std::span<const Vec> x) {
  const auto& v = f.v;
  if (f.size == 3) return (x[v[1]] - x[v[0]]).cross(x[v[2]] - x[v[0]]);
  return (x[v[2]] - x[v[0]]).cross(x[v[3]] - x[v[1]]);
}

double degrees(double cosine) {
  return std::acos(std::clamp(cosine, -1.0, 1.0)) * kDeg;
}

// A hexahedron that is an axis-aligned box, right-handed (the interior cells of MVE): its
// metrics are exact without angles. Returns false for any other hexahedron.
bool measure_box(std::span<const Vec> x, CellQuality& q) {
  const Vec a = x[1] - x[0], b = x[3] - x[0], c = x[4] - x[0];
  const double h[3] = {a.norm(), b.norm(), c.norm()};
  const double tol = 1e-12 * std::max({h[0], h[1], h[2]});
  auto axis = [&](const Vec& e, int d) {
    return e[d] > 0.0 && std::abs(e[(d + 1) % 3]) <= tol && std::abs(e[(d + 2) % 3]) <= tol;
  };
  // The three edges from corner 0 along three distinct axes, in a right-handed order.
  int da = -1, db = -1, dc = -1;
  for (int d = 0; d < 3; ++d) {
    if (axis(a, d)) da = d;
    if (axis(b, d)) db = d;
    if (axis(c, d)) dc = d;
  }
  if (da < 0 || db < 0 || dc < 0 || db != (da + 1) % 3 || dc != (da + 2) % 3) return false;
  const Vec corners[8] = {x[0],     x[0] + a,     x[0] + a + b,     x[0] + b,
                          x[0] + c, x[0] + a + c, x[0] + a + b + c, x[0] + b + c};
  for (int k = 0; k < 8; ++k)
    if ((x[k] - corners[k]).lpNorm<Eigen::Infinity>() > tol) return false;
  q.edge_ratio = static_cast<float>(std::max({h[0], h[1], h[2]}) / std::min({h[0], h[1], h[2]}));
  q.equiangle_skew = 0.0f;
  q.min_dihedral = 90.0f;
  q.scaled_jacobian = 1.0f;
  return true;
}

// Angles are compared through their cosines (acos decreases), so each face takes two arc
// cosines and the dihedral angles one.
CellQuality measure(const Shape& s, std::span<const Vec> x) {
  CellQuality q{};
  if (x.size() == 8 && measure_box(x, q)) return q;
  double shortest = INFINITY, longest = 0.0;
  // The extreme corner cosines over the triangles [0] and over the quadrilaterals [1]: eq. 3.5's
  // maximum over faces of one kind follows from them.
  double cos_min[2] = {1.0, 1.0}, cos_max[2] = {-1.0, -1.0};
  std::array<Vec, 6> unit_normal;
  for (std::size_t fi = 0; fi < s.faces.size(); ++fi) {
    const CellFace& f = s.faces[fi];
    const auto n = static_cast<std::size_t>(f.size);
    std::array<Vec, 4> edge;
    std::array<double, 4> length;
    for (std::size_t c = 0; c < n; ++c) {
      edge[c] = x[f.v[(c + 1) % n]] - x[f.v[c]];
      length[c] = edge[c].norm();
      shortest = std::min(shortest, length[c]);
      longest = std::max(longest, length[c]);
    }
    // The corner at node c lies between −edge[c−1] and edge[c]; a degenerate corner counts as 0°.
    const int kind = n == 3 ? 0 : 1;
    for (std::size_t c = 0; c < n; ++c) {
      const std::size_t b = (c + n - 1) % n;
      const double denom = length[b] * length[c];
      const double cosine = denom > 0.0 ? -edge[b].dot(edge[c]) / denom : 1.0;
      cos_min[kind] = std::min(cos_min[kind], cosine);
      cos_max[kind] = std::max(cos_max[kind], cosine);
    }
    const Vec normal = face_normal(f, x);
    const double norm = normal.norm();
    unit_normal[fi] = norm > 0.0 ? Vec(normal / norm) : Vec::Zero();
  }
  q.edge_ratio = static_cast<float>(shortest > 0.0 ? longest / shortest : INFINITY);
  double skew = 0.0;
  for (int kind = 0; kind < 2; ++kind) {
    if (cos_max[kind] < cos_min[kind]) continue;  // no face of this kind
    const double eq = kind == 0 ? 60.0 : 90.0;
    skew = std::max(
        {skew, (degrees(cos_min[kind]) - eq) / (180.0 - eq), (eq - degrees(cos_max[kind])) / eq});
  }
  q.equiangle_skew = static_cast<float>(skew);

  // Dihedral angles: π minus the angle between the outward normals of two faces on an edge; a
  // degenerate face makes it 0°.
  double cos_between = 1.0;
  for (const auto& [f, g] : s.adjacent_faces) {
    const bool degenerate = unit_normal[f].isZero(0.0) || unit_normal[g].isZero(0.0);
    cos_between = std::min(cos_between, degenerate ? -1.0 : unit_normal[f].dot(unit_normal[g]));
  }
  q.min_dihedral = static_cast<float>(180.0 - degrees(cos_between));

  double jac = INFINITY;
  for (const auto& c : s.corners) {
    const Vec a = x[c[1]] - x[c[0]], b = x[c[2]] - x[c[0]], e = x[c[3]] - x[c[0]];
    const double norms = a.norm() * b.norm() * e.norm();
    jac = std::min(jac, norms > 0.0 ? a.cross(b).dot(e) / norms : 0.0);
  }
  q.scaled_jacobian = static_cast<float>(std::min(1.0, jac * s.jacobian_scale));
  return q;
}

std::size_t rank(std::size_t n, double p) {
  return std::min(n - 1, static_cast<std::size_t>(p * (n - 1) + 0.5));
}

// Floats as unsigned integers in the same order, and back.
std::uint32_t ordered_bits(float x) {
  const auto u = std::bit_cast<std::uint32_t>(x);
  return u & 0x80000000u ? ~u : u | 0x80000000u;
}
float from_ordered_bits(std::uint32_t u) {
  return std::bit_cast<float>(u & 0x80000000u ? u & 0x7fffffffu : ~u);
}

// The values of the given ranks (ascending) among value(0 .. n−1), exactly, by radix selection:
// one counting pass over the high 16 bits of their ordered bits finds each rank's bucket, a
// second over the low 16 bits of the values in those buckets finds the value. No copy, no
// reordering, two passes whatever the number of ranks.
template <std::size_t R, class Value>
std::array<float, R> select_ranks(std::size_t n, const Value& value,
                                  const std::array<std::size_t, R>& ranks) {
  constexpr std::size_t kBins = 1u << 16;
  std::vector<std::uint32_t> high(kBins, 0);
  for (std::size_t i = 0; i < n; ++i) ++high[ordered_bits(value(i)) >> 16];
  std::array<std::uint32_t, R> bucket;
  std::array<std::size_t, R> within;
  std::size_t below = 0, b = 0;
  for (std::size_t r = 0; r < R; ++r) {
    while (below + high[b] <= ranks[r]) below += high[b++];
    bucket[r] = static_cast<std::uint32_t>(b);
    within[r] = ranks[r] - below;
  }
  // One low-bit count per distinct bucket (the ranks are ascending, so equal buckets are adjacent).
  std::array<std::size_t, R> table;
  std::vector<std::uint32_t> distinct;
  for (std::size_t r = 0; r < R; ++r) {
    if (r == 0 || bucket[r] != bucket[r - 1]) distinct.push_back(bucket[r]);
    table[r] = distinct.size() - 1;
  }
  std::vector<std::uint32_t> low(distinct.size() * kBins, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t key = ordered_bits(value(i));
    for (std::size_t d = 0; d < distinct.size(); ++d)
      if (key >> 16 == distinct[d]) ++low[d * kBins + (key & 0xffffu)];
  }
  std::array<float, R> out;
  for (std::size_t r = 0; r < R; ++r) {
    const std::uint32_t* count = low.data() + table[r] * kBins;
    std::size_t seen = 0, l = 0;
    while (seen + count[l] <= within[r]) seen += count[l++];
    out[r] = from_ordered_bits(bucket[r] << 16 | static_cast<std::uint32_t>(l));
  }
  return out;
}

float CellQuality::*member(Metric m) {
  switch (m) {
    case Metric::edge_ratio:
      return &CellQuality::edge_ratio;
    case Metric::equiangle_skew:
      return &CellQuality::equiangle_skew;
    case Metric::min_dihedral:
      return &CellQuality::min_dihedral;
    case Metric::scaled_jacobian:
      break;
  }
  return &CellQuality::scaled_jacobian;
}

}  // namespace

const char* metric_name(Metric m) {
  switch (m) {
    case Metric::edge_ratio:
      return "edge_ratio";
    case Metric::equiangle_skew:
      return "equiangle_skew";
    case Metric::min_dihedral:
      return "min_dihedral_deg";
    case Metric::scaled_jacobian:
      return "scaled_jacobian";
  }
  return "";
}

float CellQuality::get(Metric m) const {
  return this->*member(m);
}

namespace {

// Each cell's quality: known(c, q) may supply it, else it is measured.
template <class Known>
std::vector<CellQuality> qualities(const HybridMesh& mesh, int threads, const Known& known) {
  std::vector<CellQuality> out(mesh.cell_count());
  run_threads(thread_count(threads), [&](unsigned t, unsigned count) {
    auto run = [&](const auto& cells, const Shape& shape, std::size_t offset) {
      std::array<Vec, 8> x;
      for (auto [i, end] = share(cells.size(), t, count); i < end; ++i) {
        if (known(offset + i, out[offset + i])) continue;
        const auto& c = cells[i];
        for (std::size_t n = 0; n < c.size(); ++n) x[n] = mesh.nodes[c[n]];
        out[offset + i] = measure(shape, std::span<const Vec>(x.data(), c.size()));
      }
    };
    run(mesh.tets, kTet, 0);
    run(mesh.pyramids, kPyramid, mesh.tets.size());
    run(mesh.hexes, kHex, mesh.tets.size() + mesh.pyramids.size());
  });
  return out;
}

}  // namespace

std::vector<CellQuality> cell_quality(const HybridMesh& mesh, int threads) {
  return qualities(mesh, threads, [](std::size_t, CellQuality&) { return false; });
}

std::vector<CellQuality> cell_quality(const HybridMesh& mesh,
                                      const std::vector<CellQuality>& previous,
                                      std::span<const std::int64_t> unchanged_from, int threads) {
  if (unchanged_from.size() != mesh.cell_count())
    fail("internal: {} cell origins for {} cells", unchanged_from.size(), mesh.cell_count());
  return qualities(mesh, threads, [&](std::size_t c, CellQuality& q) {
    if (unchanged_from[c] < 0) return false;
    q = previous[static_cast<std::size_t>(unchanged_from[c])];
    return true;
  });
}

QualityReport summarize_quality(const HybridMesh& mesh, const std::vector<CellQuality>& q, int bins,
                                int threads) {
  QualityReport r;
  const std::size_t t = mesh.tets.size(), p = mesh.pyramids.size();
  const std::array<std::pair<std::size_t, std::size_t>, 4> ranges = {
      {{0, t}, {t, t + p}, {t + p, q.size()}, {0, q.size()}}};
  const std::size_t tasks = ranges.size() * kMetrics.size();
  run_threads(thread_count(threads), [&](unsigned worker, unsigned count) {
    for (std::size_t task = worker; task < tasks; task += count) {
      const std::size_t g = task / kMetrics.size(), m = task % kMetrics.size();
      const auto [first, last] = ranges[g];
      const float CellQuality::*field = member(kMetrics[m]);
      MetricSummary& s = r.summary[g][m];
      s.count = last - first;
      if (s.count == 0) continue;
      // Fixed ranges so histograms before and after improvement compare bin by bin.
      switch (kMetrics[m]) {
        case Metric::edge_ratio:
          s.lo = 1.0, s.hi = 11.0;
          break;
        case Metric::equiangle_skew:
          s.lo = 0.0, s.hi = 1.0;
          break;
        case Metric::min_dihedral:
          s.lo = 0.0, s.hi = 180.0;
          break;
        case Metric::scaled_jacobian:
          s.lo = -1.0, s.hi = 1.0;
          break;
      }
      s.histogram.assign(static_cast<std::size_t>(bins), 0);
      for (std::size_t c = first; c < last; ++c) {
        const double u = (q[c].*field - s.lo) / (s.hi - s.lo);
        const int b = std::clamp(static_cast<int>(u * bins), 0, bins - 1);
        ++s.histogram[static_cast<std::size_t>(b)];
      }
      const std::size_t n = s.count;
      const auto v = select_ranks(
          n, [&](std::size_t i) { return q[first + i].*field; },
          std::array<std::size_t, 7>{0, rank(n, 0.01), rank(n, 0.05), rank(n, 0.50), rank(n, 0.95),
                                     rank(n, 0.99), n - 1});
      s.min = v[0], s.p1 = v[1], s.p5 = v[2], s.p50 = v[3], s.p95 = v[4], s.p99 = v[5],
      s.max = v[6];
    }
  });
  return r;
}

}  // namespace naris
