#pragma once
// Element quality (dissertation 3.4 and eq. 3.5): edge ratio, equi-angle skew, minimum dihedral
// angle and scaled Jacobian, per cell and summarized per cell type.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris {

enum class Metric { edge_ratio, equiangle_skew, min_dihedral, scaled_jacobian };
inline constexpr std::array<Metric, 4> kMetrics = {Metric::edge_ratio, Metric::equiangle_skew,
                                                   Metric::min_dihedral, Metric::scaled_jacobian};
const char* metric_name(Metric m);

struct CellQuality {
  float edge_ratio;       // longest / shortest edge, ≥ 1
  float equiangle_skew;   // eq. 3.5 over the cell's faces, 0 (ideal) .. 1
  float min_dihedral;     // degrees
  float scaled_jacobian;  // min corner Jacobian over edge lengths; 1 for the regular tet,
                          // the regular pyramid and the cube; ≤ 0 when inverted
  float get(Metric m) const;
};

// In the mesh's cell order: tets, then pyramids, then hexes; over `threads` threads (0: every
// core).
std::vector<CellQuality> cell_quality(const HybridMesh& mesh, int threads = 0);
// The same for a mesh derived from one of known quality: a cell with unchanged_from[c] ≥ 0 is
// that cell of the former mesh, unchanged (improve_mesh says which), and takes its quality.
std::vector<CellQuality> cell_quality(const HybridMesh& mesh,
                                      const std::vector<CellQuality>& previous,
                                      std::span<const std::int64_t> unchanged_from,
                                      int threads = 0);

struct MetricSummary {
  std::size_t count = 0;
  double min = 0, p1 = 0, p5 = 0, p50 = 0, p95 = 0, p99 = 0, max = 0;
  double lo = 0, hi = 0;               // histogram range
  std::vector<std::size_t> histogram;  // equal bins over [lo, hi]
};

// Summaries for "tet", "pyramid", "hex" and "all", each for the four metrics.
struct QualityReport {
  std::array<std::string, 4> groups{"tet", "pyramid", "hex", "all"};
  std::array<std::array<MetricSummary, 4>, 4> summary;  // [group][metric]
};
QualityReport summarize_quality(const HybridMesh& mesh, const std::vector<CellQuality>& q,
                                int bins = 20, int threads = 0);

}  // namespace naris
