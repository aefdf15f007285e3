#include "mesh/mve/fill_component.h"

#include <algorithm>
#include <cmath>

namespace naris::mve {
namespace {

// Cells thinner than this (6× volume, in units of the voxel) count as invalid.
constexpr double kMinVolume6 = 1e-12;

using Points = std::array<Eigen::Vector3d, kMaxLocalPoints>;

}  // namespace

FillMeasure place_and_measure(const Tessellation& t, Points& x, bool with_shape, double floor) {
  int next = kPrivatePoint0;
  for (const auto& pp : t.privates) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (auto s : pp.mean_of) m += x[s];
    x[next++] = m / static_cast<double>(pp.mean_of.size());
  }
  // A corner's Jacobian is its tetrahedron's 6× volume over the product of its three edges;
  // compared squared (with the volume's sign) so that only the smallest needs a square root.
  double volume6 = INFINITY, shape2 = INFINITY;
  const double floor2 = floor * std::abs(floor);
  auto result = [&] {
    return FillMeasure{volume6, std::copysign(std::sqrt(std::abs(shape2)), shape2)};
  };
  auto corner = [&](double v, double product) {
    volume6 = std::min(volume6, v);
    if (with_shape) shape2 = std::min(shape2, product > 0.0 ? v * std::abs(v) / product : -1.0);
  };
  for (const auto& c : t.cells) {
    if (shape2 <= floor2) return result();
    const auto& p = c.p;
    if (c.size == 4) {
      const Eigen::Vector3d a = x[p[1]] - x[p[0]], b = x[p[2]] - x[p[0]], d = x[p[3]] - x[p[0]];
      const double v = a.cross(b).dot(d);
      if (!with_shape) {
        corner(v, 0.0);
        continue;
      }
      const double e01 = a.squaredNorm(), e02 = b.squaredNorm(), e03 = d.squaredNorm(),
                   e12 = (b - a).squaredNorm(), e13 = (d - a).squaredNorm(),
                   e23 = (d - b).squaredNorm();
      corner(v, std::max(std::max(e01 * e02 * e03, e01 * e12 * e13),
                         std::max(e02 * e12 * e23, e03 * e13 * e23)));
    } else {
      // A pyramid is valid when both diagonal splits of its base give positive tetrahedra; those
      // four tetrahedra are also its base corners' (k, k+1, k−1, apex): the base edges
      // b[k] = x[k+1] − x[k] and the lateral edges l[k] = x[apex] − x[k] give them all.
      std::array<Eigen::Vector3d, 4> base, lateral;
      for (int k = 0; k < 4; ++k)
        base[k] = x[p[(k + 1) % 4]] - x[p[k]], lateral[k] = x[p[4]] - x[p[k]];
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d& back = base[(k + 3) % 4];
        const double v = -base[k].cross(back).dot(lateral[k]);
        corner(v, with_shape ? base[k].squaredNorm() * back.squaredNorm() * lateral[k].squaredNorm()
                             : 0.0);
      }
    }
  }
  return result();
}

namespace {

void emit(const Tessellation& t, const Points& x, ComponentFill& out) {
  for (std::size_t n = 0; n < t.privates.size(); ++n) out.privates.push_back(x[kPrivatePoint0 + n]);
  for (const auto& c : t.cells) {
    if (c.size == 4)
      out.tets.push_back({c.p[0], c.p[1], c.p[2], c.p[3], 0});
    else
      out.pyramids.push_back(c.p);
  }
  for (const auto& tri : t.iso_triangles)
    out.iso_triangles.push_back({tri.p[0], tri.p[1], tri.p[2]});
}

// No table candidate fits: look for an interior apex O and, for each isosurface loop, a cap apex
// G such that O sees every face polygon (always: O is inside the cube and the polygons lie on
// its faces) and every cap triangle (G, a, b). Those are visible iff
// (G − O)·((a − O)×(b − O)) > 0 for every loop edge (a, b): a direction inside a cone of
// half-spaces, tried from a few natural guesses.
bool search_apex(const Component& comp, const Eigen::Vector3d& cube_min, const Points& x,
                 ComponentFill& out) {
  Eigen::Vector3d inside_mean = Eigen::Vector3d::Zero();
  int inside_count = 0;
  for (const auto& poly : comp.face_polygons)
    for (int n = 0; n < poly.size; ++n)
      if (poly.p[n] < kEdgePoint0) inside_mean += x[poly.p[n]], ++inside_count;
  constexpr int kSteps = 7;
  constexpr double kGrid[kSteps] = {0.5, 0.3, 0.7, 0.15, 0.85, 0.05, 0.95};
  const int tries = 1 + kSteps * kSteps * kSteps;
  std::vector<Eigen::Vector3d> caps;
  std::vector<Eigen::Vector3d> w;
  for (int attempt = 0; attempt < tries; ++attempt) {
    Eigen::Vector3d o;
    if (attempt == 0) {
      if (!inside_count) continue;
      o = inside_mean / inside_count;
    } else {
      const int g = attempt - 1;
      o = cube_min + Eigen::Vector3d(kGrid[g % kSteps], kGrid[g / kSteps % kSteps],
                                     kGrid[g / (kSteps * kSteps)]);
    }
    caps.clear();
    bool ok = true;
    for (const auto& loop : comp.loops) {
      const std::size_t n = loop.size();
      w.resize(n);
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), sum = Eigen::Vector3d::Zero();
      for (std::size_t e = 0; e < n; ++e) {
        w[e] = (x[loop[e]] - o).cross(x[loop[(e + 1) % n]] - o);
        if (w[e].norm() > 0.0) sum += w[e].normalized();
        centroid += x[loop[e]];
      }
      centroid /= static_cast<double>(n);
      // A direction u with u·w_e > 0 for every edge: first a few natural guesses, then
      // perceptron steps (add the most violated normal), which converge whenever the cone of
      // admissible directions is not empty.
      auto worst_edge = [&](const Eigen::Vector3d& u, double& margin) {
        std::size_t worst = n;
        margin = INFINITY;
        for (std::size_t e = 0; e < n; ++e) {
          const double wn = w[e].norm();
          if (!(wn > 0.0)) continue;
          const double m = u.dot(w[e]) / wn;
          if (m < margin) margin = m, worst = e;
        }
        return worst;
      };
      bool found = false;
      auto accept = [&](const Eigen::Vector3d& d) {
        if (!(d.norm() > 0.0)) return false;
        const Eigen::Vector3d u = d.normalized();
        double margin;
        worst_edge(u, margin);
        if (!(margin > 1e-9)) return false;
        caps.push_back(o + u * std::max(1e-3, (centroid - o).dot(u)));
        return true;
      };
      for (std::size_t guess = 0; guess < n + 2 && !found; ++guess)
        found = accept(guess == 0   ? sum
                       : guess == 1 ? Eigen::Vector3d(centroid - o)
                                    : w[guess - 2]);
      Eigen::Vector3d d = sum;
      for (int iter = 0; iter < 300 && !found; ++iter) {
        if (!(d.norm() > 0.0)) break;
        double margin;
        const std::size_t worst = worst_edge(d.normalized(), margin);
        if (worst == n) break;
        d += w[worst].normalized();
        found = accept(d);
      }
      if (!found) {
        ok = false;
        break;
      }
    }
    if (!ok) continue;
    auto vol = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
      return (b - a).cross(c - a).dot(o - a);
    };
    double vmin = INFINITY;
    for (const auto& poly : comp.face_polygons)
      for (int n = 1; n + 1 < poly.size; ++n)
        vmin = std::min(vmin, vol(x[poly.p[0]], x[poly.p[n + 1]], x[poly.p[n]]));
    for (std::size_t l = 0; l < comp.loops.size(); ++l) {
      const auto& loop = comp.loops[l];
      for (std::size_t e = 0; e < loop.size(); ++e)
        vmin = std::min(vmin, vol(caps[l], x[loop[(e + 1) % loop.size()]], x[loop[e]]));
    }
    if (!(vmin > kMinVolume6)) continue;

    const auto apex = static_cast<std::uint8_t>(kPrivatePoint0 + out.privates.size());
    out.privates.push_back(o);
    for (const auto& poly : comp.face_polygons) {
      const auto& p = poly.p;
      if (poly.size == 3)
        out.tets.push_back({p[0], p[2], p[1], apex, 0});
      else
        out.pyramids.push_back({p[0], p[3], p[2], p[1], apex});
    }
    for (std::size_t l = 0; l < comp.loops.size(); ++l) {
      const auto g = static_cast<std::uint8_t>(kPrivatePoint0 + out.privates.size());
      out.privates.push_back(caps[l]);
      const auto& loop = comp.loops[l];
      for (std::size_t e = 0; e < loop.size(); ++e) {
        const std::uint8_t a = loop[e], b = loop[(e + 1) % loop.size()];
        out.tets.push_back({g, b, a, apex, 0});
        out.iso_triangles.push_back({g, a, b});
      }
    }
    return true;
  }
  return false;
}

}  // namespace

void fill_component(const Component& comp, const Eigen::Vector3d& cube_min, Points& x,
                    ComponentFill& out) {
  out.clear();
  const Tessellation* least_bad = nullptr;
  double best = -INFINITY;
  const Tessellation* chosen = nullptr;
  const Tessellation* placed = nullptr;  // whose private points x holds
  double chosen_q = -INFINITY;
  for (const auto& cand : comp.candidates) {
    const FillMeasure m = place_and_measure(cand, x, true, chosen_q);
    placed = &cand;
    if (m.volume6 > kMinVolume6) {
      if (m.shape > chosen_q) chosen_q = m.shape, chosen = &cand;
      if (m.shape >= kGoodShape) break;
      continue;
    }
    if (m.volume6 > best) best = m.volume6, least_bad = &cand;
  }
  if (chosen) {
    if (chosen != placed) place_and_measure(*chosen, x, false);
    emit(*chosen, x, out);
    return;
  }
  if (search_apex(comp, cube_min, x, out)) return;
  // Nothing valid: report it and emit the least inverted candidate so the caller can count it.
  out.resolved = false;
  place_and_measure(*least_bad, x);
  emit(*least_bad, x, out);
}

void fill_component_binary(const Component& comp, const Eigen::Vector3d& cube_min, Points& x,
                           ComponentFill& out) {
  if (comp.midpoint_candidate < 0) return fill_component(comp, cube_min, x, out);
  out.clear();
  const Tessellation& t = comp.candidates[static_cast<std::size_t>(comp.midpoint_candidate)];
  int next = kPrivatePoint0;
  for (const auto& pp : t.privates) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (auto s : pp.mean_of) m += x[s];
    x[next++] = m / static_cast<double>(pp.mean_of.size());
  }
  emit(t, x, out);
}

}  // namespace naris::mve
