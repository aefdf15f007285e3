#include "mesh/mve/fill_component.h"

#include <algorithm>
#include <cmath>

namespace naris::mve {
namespace {

// Cells thinner than this (6× volume, in units of the voxel) count as invalid.
constexpr double kMinVolume6 = 1e-12;
// A valid candidate whose worst corner Jacobian reaches this is taken without trying the others:
// the search for a better one then changes no measured quality (docs/results/relocation.md).
constexpr double kGoodShape = 0.3;

using Points = std::array<Eigen::Vector3d, kMaxLocalPoints>;

double tet6(const Points& x, int a, int b, int c, int d) {
  return (x[b] - x[a]).cross(x[c] - x[a]).dot(x[d] - x[a]);
}

// The scaled Jacobian at corner a of the tetrahedron (a, b, c, d).
double corner_jacobian(const Points& x, int a, int b, int c, int d) {
  const Eigen::Vector3d e1 = x[b] - x[a], e2 = x[c] - x[a], e3 = x[d] - x[a];
  const double l = e1.norm() * e2.norm() * e3.norm();
  return l > 0 ? e1.cross(e2).dot(e3) / l : -1.0;
}

}  // namespace

double place_and_measure(const Tessellation& t, Points& x) {
  int next = kPrivatePoint0;
  for (const auto& pp : t.privates) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (auto s : pp.mean_of) m += x[s];
    x[next++] = m / static_cast<double>(pp.mean_of.size());
  }
  double vmin = INFINITY;
  for (const auto& c : t.cells) {
    const auto& p = c.p;
    if (c.size == 4) {
      vmin = std::min(vmin, tet6(x, p[0], p[1], p[2], p[3]));
    } else {
      // A pyramid is valid when both diagonal splits of its base give positive tetrahedra.
      vmin = std::min({vmin, tet6(x, p[0], p[1], p[2], p[4]), tet6(x, p[0], p[2], p[3], p[4]),
                       tet6(x, p[0], p[1], p[3], p[4]), tet6(x, p[1], p[2], p[3], p[4])});
    }
  }
  return vmin;
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

double worst_shape(const Tessellation& t, const Points& x) {
  double q = INFINITY;
  for (const auto& c : t.cells) {
    const auto& p = c.p;
    if (c.size == 4) {
      q = std::min({q, corner_jacobian(x, p[0], p[1], p[2], p[3]),
                    corner_jacobian(x, p[1], p[2], p[0], p[3]),
                    corner_jacobian(x, p[2], p[0], p[1], p[3]),
                    corner_jacobian(x, p[3], p[0], p[2], p[1])});
    } else {
      for (int k = 0; k < 4; ++k)
        q = std::min(q, corner_jacobian(x, p[k], p[(k + 1) % 4], p[(k + 3) % 4], p[4]));
    }
  }
  return q;
}

void fill_component(const Component& comp, const Eigen::Vector3d& cube_min, Points& x,
                    ComponentFill& out) {
  out.clear();
  const Tessellation* least_bad = nullptr;
  double best = -INFINITY;
  const Tessellation* chosen = nullptr;
  const Tessellation* placed = nullptr;  // whose private points x holds
  double chosen_q = -INFINITY;
  for (const auto& cand : comp.candidates) {
    const double v = place_and_measure(cand, x);
    placed = &cand;
    if (v > kMinVolume6) {
      const double q = worst_shape(cand, x);
      if (q > chosen_q) chosen_q = q, chosen = &cand;
      if (q >= kGoodShape) break;
      continue;
    }
    if (v > best) best = v, least_bad = &cand;
  }
  if (chosen) {
    if (chosen != placed) place_and_measure(*chosen, x);
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
