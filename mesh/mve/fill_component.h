#pragma once
// Fills one inside component of one cube with cells, given the positions of its local points:
// the first table candidate whose cells all have positive volume and are well shaped, else the
// best shaped of the valid ones, or else an apex found by a small search (see fill_component.cpp).
// Shared by the mesher and the table tests.
#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh/mve/case_table.h"

namespace naris::mve {

inline constexpr int kMaxLocalPoints = 96;
// A valid candidate whose worst corner Jacobian reaches this is taken without trying the others:
// searching on from there changes no measured quality (docs/results/relocation.md).
inline constexpr double kGoodShape = 0.3;

struct ComponentFill {
  // Cells and isosurface triangles in local ids; ids from kPrivatePoint0 on are new points whose
  // positions are in `privates` (id kPrivatePoint0 + n ↔ privates[n]).
  std::vector<std::array<std::uint8_t, 5>> tets;  // 4 used
  std::vector<std::array<std::uint8_t, 5>> pyramids;
  std::vector<std::array<std::uint8_t, 3>> iso_triangles;
  std::vector<Eigen::Vector3d> privates;
  bool resolved = true;  // false: nothing valid was found (cells are then unusable)
  void clear() {
    tets.clear();
    pyramids.clear();
    iso_triangles.clear();
    privates.clear();
    resolved = true;
  }
};

// x holds the positions of local points 0–25 (entries for absent points are ignored); it is
// used as scratch space beyond that. `cube_min` is the cube's lowest corner.
void fill_component(const Component& comp, const Eigen::Vector3d& cube_min,
                    std::array<Eigen::Vector3d, kMaxLocalPoints>& x, ComponentFill& out);

// A candidate's cells measured after placing its private points in x (from id kPrivatePoint0
// on): the smallest 6× tetrahedron volume (both diagonal splits of each pyramid base) and the
// smallest corner Jacobian e1·(e2×e3)/(|e1||e2||e3|), over every corner of its tetrahedra and the
// four base corners of its pyramids (1 for three perpendicular edges, 0.71 at the regular
// tetrahedron's corners, ≤ 0 for an inverted corner).
struct FillMeasure {
  double volume6;
  double shape;
};
// Without `with_shape`, the shape is not computed (left +∞). The measurement stops at the first
// cell that takes the shape to `floor` or below (the candidate cannot beat one of that shape).
FillMeasure place_and_measure(const Tessellation& t,
                              std::array<Eigen::Vector3d, kMaxLocalPoints>& x,
                              bool with_shape = true, double floor = -INFINITY);

// For binary fields: the candidate chosen in advance at midpoint isopoints (its private points
// are still placed from x). Falls back to fill_component when there is none.
void fill_component_binary(const Component& comp, const Eigen::Vector3d& cube_min,
                           std::array<Eigen::Vector3d, kMaxLocalPoints>& x, ComponentFill& out);

}  // namespace naris::mve
