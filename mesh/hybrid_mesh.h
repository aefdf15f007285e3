#pragma once
// The hybrid finite-element mesh: nodes, cells per type in VTK's linear node order with positive
// orientation, and boundary faces (triangles and quadrilaterals, outward) each with a patch id.
#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/big_vector.h"

namespace naris {

using NodeId = std::int32_t;

struct HybridMesh {
  BigVector<Eigen::Vector3d> nodes;
  BigVector<std::array<NodeId, 4>> tets;      // VTK_TETRA
  BigVector<std::array<NodeId, 5>> pyramids;  // VTK_PYRAMID: base 0-1-2-3 (normal to apex), apex 4
  BigVector<std::array<NodeId, 8>> hexes;     // VTK_HEXAHEDRON

  BigVector<std::array<NodeId, 3>> boundary_tris;
  BigVector<std::int32_t> boundary_tri_patch;
  BigVector<std::array<NodeId, 4>> boundary_quads;
  BigVector<std::int32_t> boundary_quad_patch;
  std::vector<std::string> patch_names;

  std::size_t cell_count() const { return tets.size() + pyramids.size() + hexes.size(); }
  int patch_id(const std::string& name) const;  // -1 when absent
  int add_patch(const std::string& name);       // returns the existing id if present
};

// The outward faces of each cell type, as local node indices in VTK order (a triangle's fourth
// entry is unused). Every piece of code that walks cell faces uses these tables.
struct CellFace {
  int size;
  std::array<int, 4> v;
};
inline constexpr std::array<CellFace, 4> kTetFaces = {
    {{3, {0, 2, 1, -1}}, {3, {0, 1, 3, -1}}, {3, {1, 2, 3, -1}}, {3, {0, 3, 2, -1}}}};
inline constexpr std::array<CellFace, 5> kPyramidFaces = {{{4, {0, 3, 2, 1}},
                                                           {3, {0, 1, 4, -1}},
                                                           {3, {1, 2, 4, -1}},
                                                           {3, {2, 3, 4, -1}},
                                                           {3, {3, 0, 4, -1}}}};
inline constexpr std::array<CellFace, 6> kHexFaces = {{{4, {0, 3, 2, 1}},
                                                       {4, {4, 5, 6, 7}},
                                                       {4, {0, 1, 5, 4}},
                                                       {4, {2, 3, 7, 6}},
                                                       {4, {1, 2, 6, 5}},
                                                       {4, {0, 4, 7, 3}}}};
// The faces of a cell with 4, 5 or 8 nodes.
inline std::span<const CellFace> cell_faces(int nodes) {
  if (nodes == 4) return kTetFaces;
  if (nodes == 5) return kPyramidFaces;
  return kHexFaces;
}

// The edges of each cell type as local node pairs (VTK order).
inline constexpr std::array<std::array<int, 2>, 6> kTetEdges = {
    {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}};
inline constexpr std::array<std::array<int, 2>, 8> kPyramidEdges = {
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}}};
inline constexpr std::array<std::array<int, 2>, 12> kHexEdges = {{{0, 1},
                                                                  {1, 2},
                                                                  {2, 3},
                                                                  {3, 0},
                                                                  {4, 5},
                                                                  {5, 6},
                                                                  {6, 7},
                                                                  {7, 4},
                                                                  {0, 4},
                                                                  {1, 5},
                                                                  {2, 6},
                                                                  {3, 7}}};
// The corners of each cell type for the scaled Jacobian: a node, then its three edge neighbours
// in right-handed order (the pyramid's apex has none).
inline constexpr std::array<std::array<int, 4>, 4> kTetCorners = {
    {{0, 1, 2, 3}, {1, 2, 0, 3}, {2, 0, 1, 3}, {3, 0, 2, 1}}};
inline constexpr std::array<std::array<int, 4>, 4> kPyramidCorners = {
    {{0, 1, 3, 4}, {1, 2, 0, 4}, {2, 3, 1, 4}, {3, 0, 2, 4}}};
inline constexpr std::array<std::array<int, 4>, 8> kHexCorners = {{{0, 1, 3, 4},
                                                                   {1, 2, 0, 5},
                                                                   {2, 3, 1, 6},
                                                                   {3, 0, 2, 7},
                                                                   {4, 7, 5, 0},
                                                                   {5, 4, 6, 1},
                                                                   {6, 5, 7, 2},
                                                                   {7, 6, 4, 3}}};

// The edges of a cell with 4, 5 or 8 nodes.
inline std::span<const std::array<int, 2>> cell_edges(int nodes) {
  if (nodes == 4) return kTetEdges;
  if (nodes == 5) return kPyramidEdges;
  return kHexEdges;
}

// Calls f(nodes, patch) for every boundary face, triangles then quadrilaterals; `nodes` is a
// std::span over the face's node ids and `patch` its patch id (assignable).
template <class F>
void for_each_boundary_face(HybridMesh& m, F&& f) {
  for (std::size_t i = 0; i < m.boundary_tris.size(); ++i)
    f(std::span<NodeId>(m.boundary_tris[i]), m.boundary_tri_patch[i]);
  for (std::size_t i = 0; i < m.boundary_quads.size(); ++i)
    f(std::span<NodeId>(m.boundary_quads[i]), m.boundary_quad_patch[i]);
}
template <class F>
void for_each_boundary_face(const HybridMesh& m, F&& f) {
  for (std::size_t i = 0; i < m.boundary_tris.size(); ++i)
    f(std::span<const NodeId>(m.boundary_tris[i]), m.boundary_tri_patch[i]);
  for (std::size_t i = 0; i < m.boundary_quads.size(); ++i)
    f(std::span<const NodeId>(m.boundary_quads[i]), m.boundary_quad_patch[i]);
}

// A key for the undirected edge a–b (the same for b–a).
inline std::uint64_t edge_key(NodeId a, NodeId b) {
  if (a > b) std::swap(a, b);
  return static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32 |
         static_cast<std::uint32_t>(b);
}

// Vector area ½ Σ xᵢ × xᵢ₊₁ of a polygon (along its right-hand normal); for a planar polygon
// its norm is the area, and it equals the sum over any fan triangulation.
Eigen::Vector3d polygon_vector_area(const HybridMesh& m, std::span<const NodeId> nodes);
// Area of a planar (or nearly planar) polygon: half the norm of its vector area.
double polygon_area(const HybridMesh& m, std::span<const NodeId> nodes);

// Signed volumes; positive for valid cells in VTK order.
double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d);
double pyramid_volume(const HybridMesh& m, const std::array<NodeId, 5>& p);
double hex_volume(const HybridMesh& m, const std::array<NodeId, 8>& h);
double mesh_volume(const HybridMesh& m);

// Reverses every cell and boundary face: used when the image frame has negative determinant.
void flip_orientation(HybridMesh& m);

// Removes patches without faces and renumbers the rest, keeping their order.
void remove_empty_patches(HybridMesh& m);

// Drops nodes that no cell uses and renumbers the rest, keeping their order.
void compact_nodes(HybridMesh& m);

// The boundary faces of `mesh` (same order, same patches) over their own nodes only, numbered
// in order of first use; no cells. What boundary.vtp holds.
HybridMesh boundary_surface(const HybridMesh& mesh);

}  // namespace naris
