// The generated MVE table, checked entry by entry for every configuration and every saddle
// outcome (including outcomes no trilinear data can produce), with random isopoint placements.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "mesh/mve/case_table.h"
#include "mesh/mve/fill_component.h"

namespace naris::mve {
namespace {

using Vec = Eigen::Vector3d;

std::vector<Vec> local_points(const CaseEntry& e, const std::array<double, 12>& t) {
  std::vector<Vec> x(kPrivatePoint0, Vec::Zero());
  for (int v = 0; v < 8; ++v) x[v] = Vec(kCorner[v][0], kCorner[v][1], kCorner[v][2]);
  for (int k = 0; k < 12; ++k)
    x[kEdgePoint0 + k] = x[kEdge[k][0]] + t[k] * (x[kEdge[k][1]] - x[kEdge[k][0]]);
  for (int f = 0; f < 6; ++f)
    if (e.face_point_edges[f][0] >= 0)
      x[kFacePoint0 + f] = 0.5 * (x[kEdgePoint0 + e.face_point_edges[f][0]] +
                                  x[kEdgePoint0 + e.face_point_edges[f][1]]);
  return x;
}

struct Filled {
  bool valid = true;
  bool closed = true;            // every edge of the cube's boundary polygons is used exactly twice
  double cell_volume = 0.0;      // sum of cell volumes
  double boundary_volume = 0.0;  // enclosed by face polygons + isosurface triangles
};

// Fills every component as the mesher does and measures the result independently.
Filled fill(const CaseEntry& e, const std::array<double, 12>& t) {
  Filled r;
  const auto base = local_points(e, t);
  auto enclosed = [](const Vec& a, const Vec& b, const Vec& c) { return a.dot(b.cross(c)) / 6.0; };
  std::map<std::pair<int, int>, int> boundary_edges;
  for (int f = 0; f < 6; ++f)
    for (const auto& p : e.face_polygons[f]) {
      for (int i = 1; i + 1 < p.size; ++i)
        r.boundary_volume += enclosed(base[p.p[0]], base[p.p[i]], base[p.p[i + 1]]);
      for (int k = 0; k < p.size; ++k)
        ++boundary_edges[{std::min(p.p[k], p.p[(k + 1) % p.size]),
                          std::max(p.p[k], p.p[(k + 1) % p.size])}];
    }
  for (const auto& comp : e.components) {
    std::array<Vec, kMaxLocalPoints> x;
    std::copy(base.begin(), base.end(), x.begin());
    ComponentFill out;
    fill_component(comp, Vec::Zero(), x, out);
    r.valid = r.valid && out.resolved;
    std::vector<Vec> pts(base);
    pts.insert(pts.end(), out.privates.begin(), out.privates.end());
    auto tet = [&](int a, int b, int c, int d) {
      return (pts[b] - pts[a]).cross(pts[c] - pts[a]).dot(pts[d] - pts[a]) / 6.0;
    };
    for (const auto& c : out.tets) {
      const double v = tet(c[0], c[1], c[2], c[3]);
      r.valid = r.valid && v > 0.0;
      r.cell_volume += v;
    }
    for (const auto& c : out.pyramids) {
      const double v1 = tet(c[0], c[1], c[2], c[4]), v2 = tet(c[0], c[2], c[3], c[4]);
      r.valid = r.valid && v1 > 0.0 && v2 > 0.0 && tet(c[0], c[1], c[3], c[4]) > 0.0 &&
                tet(c[1], c[2], c[3], c[4]) > 0.0;
      r.cell_volume += v1 + v2;
    }
    // Private point ids restart in every component: edges that touch one are counted per
    // component, edges between cube points over the whole cube.
    std::map<std::pair<int, int>, int> private_edges;
    for (const auto& tri : out.iso_triangles) {
      r.boundary_volume += enclosed(pts[tri[0]], pts[tri[1]], pts[tri[2]]);
      for (int k = 0; k < 3; ++k) {
        const std::pair<int, int> edge{std::min(tri[k], tri[(k + 1) % 3]),
                                       std::max(tri[k], tri[(k + 1) % 3])};
        ++(edge.second >= kPrivatePoint0 ? private_edges : boundary_edges)[edge];
      }
    }
    for (const auto& [edge, n] : private_edges) r.closed = r.closed && n == 2;
  }
  for (const auto& [edge, n] : boundary_edges) r.closed = r.closed && n == 2;
  return r;
}

template <class F>
void for_each_entry(F&& f) {
  for (int config = 0; config < 256; ++config) {
    const auto choice = choice_faces(static_cast<std::uint8_t>(config));
    for (int mask = 0; mask < 64; ++mask)
      if ((mask & ~choice) == 0)
        f(static_cast<std::uint8_t>(config), static_cast<std::uint8_t>(mask));
  }
}

// The 24 rotations of the cube as permutations of its vertices, generated from quarter turns
// about x and z (dissertation 3.2.1 reduces the 256 configurations by rotation alone).
std::vector<std::array<int, 8>> cube_rotations() {
  auto vertex_at = [](int x, int y, int z) {
    for (int v = 0; v < 8; ++v)
      if (kCorner[v][0] == x && kCorner[v][1] == y && kCorner[v][2] == z) return v;
    return -1;
  };
  std::array<int, 8> about_x{}, about_z{};
  for (int v = 0; v < 8; ++v) {
    const auto& c = kCorner[v];
    about_x[v] = vertex_at(c[0], 1 - c[2], c[1]);
    about_z[v] = vertex_at(1 - c[1], c[0], c[2]);
  }
  std::vector<std::array<int, 8>> group{{0, 1, 2, 3, 4, 5, 6, 7}};
  for (std::size_t i = 0; i < group.size(); ++i)
    for (const auto& g : {about_x, about_z}) {
      std::array<int, 8> composed{};
      for (int v = 0; v < 8; ++v) composed[v] = g[group[i][v]];
      if (std::find(group.begin(), group.end(), composed) == group.end()) group.push_back(composed);
    }
  return group;
}

std::size_t entry_count() {
  std::size_t entries = 0;
  for_each_entry([&](std::uint8_t, std::uint8_t) { ++entries; });
  return entries;
}

TEST(CaseTable, CoversEveryConfigurationAndFaceChoice) {
  // Every face with two inside vertices, on a diagonal or on an edge, has two tessellations.
  std::size_t expected = 0;
  for (int config = 0; config < 256; ++config) {
    std::size_t ways = 1;
    for (const auto& face : kFace) {
      int inside = 0;
      for (int v : face) inside += config >> v & 1;
      if (inside == 2) ways *= 2;
    }
    expected += ways;
  }
  EXPECT_EQ(entry_count(), expected);
  // 256 configurations, 23 major cases under the 24 rotations; a rotation maps ambiguous faces
  // to ambiguous faces, so every configuration of a case has as many.
  const auto rotations = cube_rotations();
  ASSERT_EQ(rotations.size(), 24u);
  std::set<int> classes;
  for (int config = 0; config < 256; ++config) {
    int smallest = config;
    for (const auto& r : rotations) {
      int image = 0;
      for (int v = 0; v < 8; ++v) image |= (config >> v & 1) << r[v];
      smallest = std::min(smallest, image);
      EXPECT_EQ(std::popcount(ambiguous_faces(static_cast<std::uint8_t>(config))),
                std::popcount(ambiguous_faces(static_cast<std::uint8_t>(image))));
    }
    classes.insert(smallest);
  }
  EXPECT_EQ(classes.size(), 23u);
}

TEST(CaseTable, FaceRulesGiveTheExpectedPolygonCounts) {
  for_each_entry([&](std::uint8_t config, std::uint8_t mask) {
    const auto& e = case_entry(config, mask);
    // Bits of faces without a choice are ignored.
    EXPECT_EQ(&e, &case_entry(config, mask | (~choice_faces(config) & 0x3f)));
    for (int f = 0; f < 6; ++f) {
      int inside = 0;
      for (int v : kFace[f]) inside += config >> v & 1;
      const auto& polys = e.face_polygons[f];
      const bool diagonal = ambiguous_faces(config) >> f & 1;
      const std::size_t expected = inside == 4   ? 1
                                   : inside == 3 ? 3
                                   : inside == 2
                                       ? (mask >> f & 1 ? (diagonal ? 3 : 1) : (diagonal ? 2 : 3))
                                   : inside == 1 ? 1
                                                 : 0;
      ASSERT_EQ(polys.size(), expected) << "config " << int(config) << " face " << f;
      if (inside == 4 || (inside == 2 && !diagonal && (mask >> f & 1))) {
        EXPECT_EQ(polys[0].size, 4);
      }
    }
  });
}

TEST(CaseTable, EveryEntryFillsItsRegionAtMidpointIsopoints) {
  // Binary masks (labelmaps) put every isopoint at the middle of its edge; every entry,
  // including saddle combinations that no trilinear data can produce, must resolve there.
  std::array<double, 12> mid;
  mid.fill(0.5);
  for_each_entry([&](std::uint8_t config, std::uint8_t mask) {
    const Filled r = fill(case_entry(config, mask), mid);
    ASSERT_TRUE(r.valid) << "config " << int(config) << " mask " << int(mask);
    ASSERT_TRUE(r.closed) << "config " << int(config) << " mask " << int(mask);
    ASSERT_NEAR(r.cell_volume, r.boundary_volume, 1e-12) << "config " << int(config);
  });
}

// Vertex values drawn with magnitudes over three decades decide both the isopoints and the
// saddle outcomes, as real data would: every configuration, every realizable outcome.
TEST(CaseTable, EveryConfigurationFillsItsRegionForRandomVertexValues) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 0.0);
  std::set<std::pair<int, int>> realized;
  std::size_t unresolved = 0, samples = 0;
  for (int config = 1; config < 256; ++config) {
    std::array<int, 6> seen_connected{}, seen_separated{}, seen_trapezoid{}, seen_face_point{};
    for (int s = 0; s < 600; ++s) {
      std::array<double, 8> f;
      for (int v = 0; v < 8; ++v) f[v] = ((config >> v & 1) ? 1.0 : -1.0) * std::pow(10.0, u(rng));
      std::array<double, 12> t;
      for (int e = 0; e < 12; ++e) {
        const double fa = f[kEdge[e][0]], fb = f[kEdge[e][1]];
        t[e] = (fa > 0) != (fb > 0) ? std::clamp(fa / (fa - fb), 1e-3, 1.0 - 1e-3) : 0.5;
      }
      std::uint8_t mask = 0;
      const auto amb = ambiguous_faces(static_cast<std::uint8_t>(config));
      const auto edge_face = edge_faces(static_cast<std::uint8_t>(config));
      for (int fc = 0; fc < 6; ++fc) {
        const auto& c = kFace[fc];
        if (edge_face >> fc & 1) {  // either tessellation must fill: a coin decides
          if (rng() & 1) {
            mask |= static_cast<std::uint8_t>(1u << fc);
            ++seen_trapezoid[fc];
          } else {
            ++seen_face_point[fc];
          }
          continue;
        }
        if (!(amb >> fc & 1)) continue;
        const bool first = f[c[0]] > 0;
        const double pin = first ? f[c[0]] * f[c[2]] : f[c[1]] * f[c[3]];
        const double pout = first ? f[c[1]] * f[c[3]] : f[c[0]] * f[c[2]];
        if (pin > pout) {
          mask |= static_cast<std::uint8_t>(1u << fc);
          ++seen_connected[fc];
        } else {
          ++seen_separated[fc];
        }
      }
      realized.insert({config, mask});
      const Filled r = fill(case_entry(static_cast<std::uint8_t>(config), mask), t);
      ++samples;
      if (!r.valid) {
        ++unresolved;
        ADD_FAILURE() << "unresolved: config " << config << " mask " << int(mask) << " t "
                      << ::testing::PrintToString(t);
        continue;
      }
      // Cells exactly fill the closed region the face polygons and the isosurface enclose.
      ASSERT_TRUE(r.closed) << "config " << config << " mask " << int(mask);
      ASSERT_NEAR(r.cell_volume, r.boundary_volume, 1e-9) << "config " << config;
    }
    const auto amb = ambiguous_faces(static_cast<std::uint8_t>(config));
    const auto edge_face = edge_faces(static_cast<std::uint8_t>(config));
    for (int fc = 0; fc < 6; ++fc) {
      if (edge_face >> fc & 1) {
        EXPECT_GT(seen_trapezoid[fc], 0) << "config " << config << " face " << fc;
        EXPECT_GT(seen_face_point[fc], 0) << "config " << config << " face " << fc;
      }
      if (!(amb >> fc & 1)) continue;
      EXPECT_GT(seen_connected[fc], 0) << "config " << config << " face " << fc;
      EXPECT_GT(seen_separated[fc], 0) << "config " << config << " face " << fc;
    }
  }
  std::printf(
      "[ info ] %zu (configuration, face choices) pairs realized of %zu table entries; "
      "%zu of %zu samples unresolved\n",
      realized.size() + 1, entry_count(), unresolved, samples);
  EXPECT_EQ(unresolved, 0u);
}

// A face shared by two cubes is tessellated from its four vertex flags and its choice (saddle
// outcome or trapezoid) alone, so both cubes see the same polygons, in opposite orientation.
TEST(CaseTable, SharedFacesAreTessellatedIdenticallyFromBothSides) {
  // Map a local point of the cube at `origin` to a global grid entity.
  using Key = std::tuple<char, int, int, int, int>;
  auto global = [](int local, std::array<int, 3> origin, const CaseEntry&) -> Key {
    if (local < kEdgePoint0)
      return {'v', origin[0] + kCorner[local][0], origin[1] + kCorner[local][1],
              origin[2] + kCorner[local][2], 0};
    if (local < kFacePoint0) {
      const int e = local - kEdgePoint0, a = kEdge[e][0];
      return {'e', origin[0] + kCorner[a][0], origin[1] + kCorner[a][1], origin[2] + kCorner[a][2],
              e / 4};
    }
    const int f = local - kFacePoint0;
    std::array<int, 3> o = origin;
    if (f % 2 == 1) ++o[f / 2];
    return {'f', o[0], o[1], o[2], f / 2};
  };
  auto canonical = [](std::vector<Key> cycle, bool reverse) {
    if (reverse) std::reverse(cycle.begin(), cycle.end());
    std::rotate(cycle.begin(), std::min_element(cycle.begin(), cycle.end()), cycle.end());
    return cycle;
  };
  std::size_t pairs = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int fa = 2 * axis + 1, fb = 2 * axis;  // +axis face of A is −axis face of B
    std::array<int, 3> ob{0, 0, 0};
    ob[axis] = 1;
    for_each_entry([&](std::uint8_t ca, std::uint8_t ma) {
      const auto& ea = case_entry(ca, ma);
      // B's vertices on the shared face copy A's; its other four vary freely.
      for (int free = 0; free < 16; ++free) {
        std::uint8_t cb = 0;
        int bit = 0;
        for (int v = 0; v < 8; ++v) {
          const bool on_shared =
              std::find(kFace[fb].begin(), kFace[fb].end(), v) != kFace[fb].end();
          bool inside;
          if (on_shared) {
            std::array<int, 3> p{kCorner[v][0], kCorner[v][1], kCorner[v][2]};
            int va = 0;
            for (; va < 8; ++va)
              if (kCorner[va][0] == p[0] + (axis == 0) && kCorner[va][1] == p[1] + (axis == 1) &&
                  kCorner[va][2] == p[2] + (axis == 2))
                break;
            inside = ca >> va & 1;
          } else {
            inside = free >> bit++ & 1;
          }
          cb |= static_cast<std::uint8_t>(inside << v);
        }
        const std::uint8_t mb = (ma >> fa & 1) ? static_cast<std::uint8_t>(1u << fb) : 0;
        const auto& eb = case_entry(cb, mb);
        std::multiset<std::vector<Key>> sa, sb;
        for (const auto& p : ea.face_polygons[fa]) {
          std::vector<Key> c;
          for (int i = 0; i < p.size; ++i) c.push_back(global(p.p[i], {0, 0, 0}, ea));
          sa.insert(canonical(c, false));
        }
        for (const auto& p : eb.face_polygons[fb]) {
          std::vector<Key> c;
          for (int i = 0; i < p.size; ++i) c.push_back(global(p.p[i], ob, eb));
          sb.insert(canonical(c, true));
        }
        ASSERT_EQ(sa, sb) << "axis " << axis << " configs " << int(ca) << "/" << int(cb);
        ++pairs;
      }
    });
  }
  EXPECT_GT(pairs, 3u * 256u * 16u - 1u);
}

}  // namespace
}  // namespace naris::mve
