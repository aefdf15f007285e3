#include "mesh/quality/quality.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

namespace naris {
namespace {

using Vec = Eigen::Vector3d;
constexpr double kDeg = 180.0 / std::numbers::pi;

// Cell shapes in VTK order: outward faces (the shared tables), and for each corner three
// neighbours that form a right-handed frame in a valid cell.
struct Shape {
  std::span<const CellFace> faces;
  std::vector<std::array<int, 4>> corners;  // vertex, then its three neighbours
  double jacobian_scale;                    // makes the ideal cell's corners 1
};

const Shape kTet{kTetFaces,
                 {{{0, 1, 2, 3}}, {{1, 2, 0, 3}}, {{2, 0, 1, 3}}, {{3, 0, 2, 1}}},
                 std::numbers::sqrt2};
const Shape kPyramid{kPyramidFaces,
                     {{{0, 1, 3, 4}}, {{1, 2, 0, 4}}, {{2, 3, 1, 4}}, {{3, 0, 2, 4}}},
                     std::numbers::sqrt2};
const Shape kHex{kHexFaces,
                 {{{0, 1, 3, 4}},
                  {{1, 2, 0, 5}},
                  {{2, 3, 1, 6}},
                  {{3, 0, 2, 7}},
                  {{4, 7, 5, 0}},
                  {{5, 4, 6, 1}},
                  {{6, 5, 7, 2}},
                  {{7, 6, 4, 3}}},
                 1.0};

Vec face_normal(const CellFace& f, std::span<const Vec> x) {
  const auto& v = f.v;
  if (f.size == 3) return (x[v[1]] - x[v[0]]).cross(x[v[2]] - x[v[0]]);
  return (x[v[2]] - x[v[0]]).cross(x[v[3]] - x[v[1]]);
}

bool has(const CellFace& f, int node) {
  return std::find(f.v.begin(), f.v.begin() + f.size, node) != f.v.begin() + f.size;
}

CellQuality measure(const Shape& s, std::span<const Vec> x) {
  CellQuality q{};
  double shortest = INFINITY, longest = 0.0, skew = 0.0;
  for (const auto& f : s.faces) {
    const auto n = static_cast<std::size_t>(f.size);
    const double eq = n == 3 ? 60.0 : 90.0;
    double amax = 0.0, amin = 180.0;
    for (std::size_t c = 0; c < n; ++c) {
      const Vec a = x[f.v[(c + n - 1) % n]] - x[f.v[c]], b = x[f.v[(c + 1) % n]] - x[f.v[c]];
      const double len = b.norm();
      shortest = std::min(shortest, len);
      longest = std::max(longest, len);
      const double denom = a.norm() * len;
      const double angle =
          denom > 0.0 ? std::acos(std::clamp(a.dot(b) / denom, -1.0, 1.0)) * kDeg : 0.0;
      amax = std::max(amax, angle);
      amin = std::min(amin, angle);
    }
    skew = std::max({skew, (amax - eq) / (180.0 - eq), (eq - amin) / eq});
  }
  q.edge_ratio = static_cast<float>(shortest > 0.0 ? longest / shortest : INFINITY);
  q.equiangle_skew = static_cast<float>(skew);

  // Dihedral angles: π minus the angle between the outward normals of two faces on an edge.
  double min_dihedral = 180.0;
  for (std::size_t f = 0; f < s.faces.size(); ++f)
    for (std::size_t g = f + 1; g < s.faces.size(); ++g) {
      int shared = 0;
      for (int k = 0; k < s.faces[f].size; ++k) shared += has(s.faces[g], s.faces[f].v[k]);
      if (shared != 2) continue;
      const Vec n1 = face_normal(s.faces[f], x), n2 = face_normal(s.faces[g], x);
      const double d = n1.norm() * n2.norm();
      const double between =
          d > 0.0 ? std::acos(std::clamp(n1.dot(n2) / d, -1.0, 1.0)) * kDeg : 180.0;
      min_dihedral = std::min(min_dihedral, 180.0 - between);
    }
  q.min_dihedral = static_cast<float>(min_dihedral);

  double jac = INFINITY;
  for (const auto& c : s.corners) {
    const Vec a = x[c[1]] - x[c[0]], b = x[c[2]] - x[c[0]], e = x[c[3]] - x[c[0]];
    const double norms = a.norm() * b.norm() * e.norm();
    jac = std::min(jac, norms > 0.0 ? a.cross(b).dot(e) / norms : 0.0);
  }
  q.scaled_jacobian = static_cast<float>(std::min(1.0, jac * s.jacobian_scale));
  return q;
}

double percentile(std::vector<float>& v, double p) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
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
  switch (m) {
    case Metric::edge_ratio:
      return edge_ratio;
    case Metric::equiangle_skew:
      return equiangle_skew;
    case Metric::min_dihedral:
      return min_dihedral;
    case Metric::scaled_jacobian:
      return scaled_jacobian;
  }
  return 0.0f;
}

std::vector<CellQuality> cell_quality(const HybridMesh& mesh) {
  std::vector<CellQuality> out;
  out.reserve(mesh.cell_count());
  auto run = [&](const auto& cells, const Shape& shape) {
    std::array<Vec, 8> x;
    for (const auto& c : cells) {
      for (std::size_t n = 0; n < c.size(); ++n) x[n] = mesh.nodes[c[n]];
      out.push_back(measure(shape, std::span<const Vec>(x.data(), c.size())));
    }
  };
  run(mesh.tets, kTet);
  run(mesh.pyramids, kPyramid);
  run(mesh.hexes, kHex);
  return out;
}

QualityReport summarize_quality(const HybridMesh& mesh, const std::vector<CellQuality>& q,
                                int bins) {
  QualityReport r;
  const std::size_t t = mesh.tets.size(), p = mesh.pyramids.size();
  const std::array<std::pair<std::size_t, std::size_t>, 4> ranges = {
      {{0, t}, {t, t + p}, {t + p, q.size()}, {0, q.size()}}};
  for (std::size_t g = 0; g < 4; ++g) {
    for (std::size_t m = 0; m < kMetrics.size(); ++m) {
      std::vector<float> v;
      v.reserve(ranges[g].second - ranges[g].first);
      for (std::size_t c = ranges[g].first; c < ranges[g].second; ++c)
        v.push_back(q[c].get(kMetrics[m]));
      MetricSummary& s = r.summary[g][m];
      s.count = v.size();
      if (v.empty()) continue;
      s.min = *std::min_element(v.begin(), v.end());
      s.max = *std::max_element(v.begin(), v.end());
      s.p1 = percentile(v, 0.01);
      s.p5 = percentile(v, 0.05);
      s.p50 = percentile(v, 0.50);
      s.p95 = percentile(v, 0.95);
      s.p99 = percentile(v, 0.99);
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
      for (float x : v) {
        const double u = (x - s.lo) / (s.hi - s.lo);
        const int b = std::clamp(static_cast<int>(u * bins), 0, bins - 1);
        ++s.histogram[static_cast<std::size_t>(b)];
      }
    }
  }
  return r;
}

}  // namespace naris
