#pragma once
// The FE velocity field of a naris solution on its hybrid mesh, for particle tracking.
//
// Location walks from cell to face neighbour along the straight segment between two points:
// each cell is bounded by the triangles of its faces (a quadrilateral split into two along the
// diagonal through its lowest node id, the same split from both sides, so the cells tile the
// domain without gaps), the walk leaves a cell through the first triangle the segment crosses
// outwards (which also holds in the non-convex cells whose faces a warp or a relocation bent),
// and a boundary face ends it: leaving the domain is found exactly, never by a distance search. A
// point's first cell comes from a uniform bucket grid (O(1)), then the same walk from the centre of
// a candidate cell. Velocity is the solver's interpolant (P1 tetrahedra, Q1 hexahedra, the rational
// pyramid) at the point's reference coordinates (barycentric in tetrahedra, Newton's inverse
// mapping in pyramids and hexahedra). In a cell that touches the wall, w = Σ N_i over its nodes off
// the wall grows like the distance from the wall's nodes, and the velocity's component along ∇w is
// scaled by w: the wall-normal velocity then vanishes as d² at a no-slip wall, as continuity
// requires (the plain interpolant's u·n ∝ d draws tracers and small particles onto the wall).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/big_vector.h"
#include "mesh/hybrid_mesh.h"
#include "solver/particles/flow_domain.h"

namespace naris::particles {

class MeshFlow : public FlowDomain {
 public:
  // `mesh` in millimetres (as in mesh.h5), `velocity` per node in m/s; positions are metres.
  // `open_patches` are the inlet and outlet: no wall there for interception. Throws
  // naris::Error when a cell face has neither a neighbour nor a boundary face (an open mesh).
  MeshFlow(const HybridMesh& mesh, std::span<const Vec3> velocity,
           const std::vector<int>& open_patches);

  Vec3 velocity(const Vec3& from, int& cell, const Vec3& x) const override;
  Passage pass(const Vec3& a, const Vec3& b, int& cell, double radius) const override;
  double cell_size(int cell) const override { return size_[static_cast<std::size_t>(cell)]; }
  int locate(const Vec3& x) const override;
  const std::vector<std::string>& patch_names() const override { return patch_names_; }

  std::size_t cells() const { return count_.size(); }
  // The velocity in cell `cell` at x (extrapolating when x is outside it), with the law near the
  // wall (as velocity()) or the plain interpolant.
  Vec3 velocity_in_cell(int cell, const Vec3& x, bool wall_law = true) const;
  Vec3 cell_centre(int cell) const;
  std::span<const Vec3> nodes() const { return {nodes_.data(), nodes_.size()}; }

 private:
  // A face plane of a cell (a triangle of the face): n·x − offset > 0 outside. The unit normal
  // is stored in single precision and the offset computed from it, so that the two cells of a
  // face hold exactly opposite planes.
  struct Plane {
    double offset;
    std::array<float, 3> unit;
    std::int8_t face;  // the cell's local face
    std::int8_t half;  // a quadrilateral's triangle: 0 or 1 (a triangle face: 0)
    Vec3 n() const { return {unit[0], unit[1], unit[2]}; }
  };
  std::span<const Plane> planes_of(int cell) const {
    const auto c = static_cast<std::size_t>(cell);
    return {&planes_[plane_start_[c]], plane_start_[c + 1] - plane_start_[c]};
  }
  std::span<const NodeId> cell_nodes(int cell) const {
    return {&nodes_of_[8 * static_cast<std::size_t>(cell)],
            static_cast<std::size_t>(count_[static_cast<std::size_t>(cell)])};
  }
  bool inside(int cell, const Vec3& x, double tolerance) const;
  // Where the line a + t·d crosses plane p outwards, shifted inwards by wall_shift; NaN if it
  // does not face along d.
  double plane_crossing(int cell, const Plane& p, const Vec3& a, const Vec3& d,
                        double radius) const;
  // `radius` on a wall face of the cell (interception), 0 elsewhere.
  double wall_shift(int cell, int face, double radius) const;
  // The nodes of plane p's triangle, counter-clockwise seen from outside the cell.
  std::array<NodeId, 3> triangle(int cell, const Plane& p) const;
  // Whether the line a + t·d crosses plane p's triangle outwards (Plücker signs: exactly
  // opposite on the two sides of an edge, so a line through an edge cannot slip between the two
  // triangles), and where.
  bool crosses_outwards(int cell, const Plane& p, const Vec3& a, const Vec3& d, double& t) const;
  // The face triangle through which the line a + t·d leaves `cell` after t_now, and its t: the
  // first triangle the line crosses outwards; with `radius`, a wall plane shifted inwards by it
  // counts too. nullptr: no plane faces along d.
  const Plane* exit_plane(int cell, int entry, const Vec3& a, const Vec3& d, double t_now,
                          double radius, double& t) const;
  // Shape values (and physical gradients, when asked) of `cell` at x; returns the node count.
  int shape(int cell, const Vec3& x, std::array<double, 8>& value,
            std::array<Vec3, 8>* gradient) const;

  BigVector<Vec3> nodes_;         // m
  BigVector<Vec3> velocity_;      // m/s
  BigVector<NodeId> nodes_of_;    // 8 per cell
  BigVector<std::int8_t> count_;  // 4, 5 or 8
  BigVector<float> size_;         // cube root of the volume (m)
  BigVector<Plane> planes_;       // per cell, its faces' planes (a quadrilateral gives two)
  BigVector<std::uint32_t> plane_start_;
  // Per cell and local face: the neighbour (≥ 0) or −1 − the boundary face (tris, then quads).
  BigVector<std::int32_t> neighbour_;
  BigVector<std::int8_t> neighbour_face_;  // the neighbour's local face
  std::vector<std::int32_t> boundary_patch_;
  std::vector<bool> open_patch_;
  BigVector<std::uint8_t> wall_node_;      // 1: on a wall face (no slip)
  BigVector<std::uint8_t> wall_touching_;  // 1: the cell has a node on the wall
  BigVector<std::uint8_t> affine_;         // 1: a parallelepiped hexahedron
  BigVector<std::uint8_t> convex_;         // 1: convex, with plane faces
  std::vector<std::string> patch_names_;

  // Bucket grid: the cells whose bounding box meets each bucket (CSR).
  Vec3 lo_ = Vec3::Zero();
  double bucket_ = 1.0;
  std::array<int, 3> dims_{0, 0, 0};
  std::vector<std::uint32_t> bucket_start_;
  std::vector<std::int32_t> bucket_cells_;
};

}  // namespace naris::particles
