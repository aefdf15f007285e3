// Cell quality against closed forms (a box, the corner tetrahedron), a box's shortcut against
// the general computation on the same box turned, and the summary's order statistics against a
// full sort.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "mesh/quality/quality.h"

namespace naris {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

HybridMesh box(const Eigen::Matrix3d& turn, const Eigen::Vector3d& size) {
  HybridMesh m;
  const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const auto& c : corner)
    m.nodes.push_back(turn * Eigen::Vector3d(c[0] * size[0], c[1] * size[1], c[2] * size[2]) +
                      Eigen::Vector3d(3.1, -2.0, 7.5));
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  return m;
}

TEST(Quality, AnAxisAlignedBoxAndTheSameBoxTurned) {
  const Eigen::Vector3d size(1.0, 2.0, 0.5);
  const CellQuality q = cell_quality(box(Eigen::Matrix3d::Identity(), size))[0];
  EXPECT_FLOAT_EQ(q.edge_ratio, 4.0f);
  EXPECT_FLOAT_EQ(q.equiangle_skew, 0.0f);
  EXPECT_FLOAT_EQ(q.min_dihedral, 90.0f);
  EXPECT_FLOAT_EQ(q.scaled_jacobian, 1.0f);
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const CellQuality t = cell_quality(box(turn, size))[0];
  EXPECT_NEAR(t.edge_ratio, 4.0, 1e-5);
  EXPECT_NEAR(t.equiangle_skew, 0.0, 1e-5);
  EXPECT_NEAR(t.min_dihedral, 90.0, 1e-4);
  EXPECT_NEAR(t.scaled_jacobian, 1.0, 1e-5);
}

TEST(Quality, TheCornerTetrahedron) {
  HybridMesh m;
  for (const auto& x : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                        Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)})
    m.nodes.push_back(x);
  m.tets.push_back({0, 1, 2, 3});
  const CellQuality q = cell_quality(m)[0];
  EXPECT_NEAR(q.edge_ratio, std::sqrt(2.0), 1e-6);
  // Right isosceles faces: (90° − 60°)/120° = (60° − 45°)/60° = 0.25.
  EXPECT_NEAR(q.equiangle_skew, 0.25, 1e-6);
  // Between the slanted face and a coordinate face: 180° − acos(−1/√3).
  EXPECT_NEAR(q.min_dihedral, 180.0 - std::acos(-1.0 / std::sqrt(3.0)) * kDeg, 1e-4);
}

TEST(Quality, OrderStatisticsAreThoseOfASortedList) {
  HybridMesh m;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int t = 0; t < 2001; ++t) {
    const auto base = static_cast<NodeId>(m.nodes.size());
    m.nodes.push_back(Eigen::Vector3d(0, 0, 0));
    m.nodes.push_back(Eigen::Vector3d(1, 0, 0));
    m.nodes.push_back(Eigen::Vector3d(u(rng), 1, 0));
    m.nodes.push_back(Eigen::Vector3d(u(rng), u(rng), 0.05 + u(rng)));
    m.tets.push_back({base, base + 1, base + 2, base + 3});
  }
  const auto q = cell_quality(m);
  const QualityReport r = summarize_quality(m, q, 20, 2);
  for (std::size_t k = 0; k < kMetrics.size(); ++k) {
    std::vector<float> v;
    for (const auto& c : q) v.push_back(c.get(kMetrics[k]));
    std::sort(v.begin(), v.end());
    auto at = [&](double p) { return v[static_cast<std::size_t>(p * (v.size() - 1) + 0.5)]; };
    for (const MetricSummary& s : {r.summary[0][k], r.summary[3][k]}) {
      EXPECT_EQ(s.count, v.size());
      EXPECT_EQ(s.min, v.front());
      EXPECT_EQ(s.p1, at(0.01));
      EXPECT_EQ(s.p5, at(0.05));
      EXPECT_EQ(s.p50, at(0.50));
      EXPECT_EQ(s.p95, at(0.95));
      EXPECT_EQ(s.p99, at(0.99));
      EXPECT_EQ(s.max, v.back());
    }
    EXPECT_EQ(r.summary[2][k].count, 0u);  // no hexahedra
  }
}

}  // namespace
}  // namespace naris
