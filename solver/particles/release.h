#pragma once
// Where particles start: sets of points on the inlet patch (the naris) or given by the user.
// Positions are metres (the mesh's millimetres × 10⁻³), like the tracker's.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/particles/flow_domain.h"

namespace naris::particles {

struct ReleaseSet {
  std::vector<std::string> groups;  // names, indexed by `group`
  std::vector<Vec3> points;
  std::vector<int> group;
  void add(const Vec3& x, int g) {
    points.push_back(x);
    group.push_back(g);
  }
};

// The inlet patch as a plane polygon: its centre, outward normal, long and short axes (the
// principal axes of its area; the long axis points "up" — against gravity — when it can, and
// for a nearly round naris is "up" projected on the plane; with "up" across the plane its
// largest component is positive), and its outline (the patch's own boundary edges).
struct InletShape {
  Vec3 centre = Vec3::Zero(), normal = Vec3::UnitZ();
  Vec3 long_axis = Vec3::UnitX(), short_axis = Vec3::UnitY();
  double area = 0.0;
  std::vector<std::array<Vec3, 3>> triangles;  // the patch, split as the tracker splits it
  std::vector<std::array<Vec3, 2>> outline;
  bool contains(const Vec3& x) const;  // x's projection along the normal lies on the patch
  // The patch's triangle x projects onto along the normal (nullptr: none; a triangle whose
  // normal is more than 84° from the patch's is a fold and skipped), and x moved along the
  // normal onto it: a patch cut from a scan is planar only to a fraction of a voxel.
  const std::array<Vec3, 3>* triangle_under(const Vec3& x) const;
  Vec3 onto_patch(const Vec3& x) const;
  double distance_to_outline(const Vec3& x) const;
};
// Any planar patch (the outlet too); throws naris::Error when the patch has no faces.
InletShape inlet_shape(const HybridMesh& mesh, int patch, const Vec3& up);

// A seed x on the inlet moved onto its faces, then inside along the inward normal by the least
// of 0.1 µm × 4^k (k = 0 … 5, so at most 0.1024 mm) that `domain` locates: where a warped face is
// split into two planes, the cells' half-spaces leave a sliver at the fold. Returns the cell
// (x moved), or −1 when none of the steps is inside.
int seed_inside(const InletShape& inlet, const FlowDomain& domain, Vec3& x);

// Section 4.3.1's three groups on the long axis of the naris, each `count` points at least
// `offset` (m) from its outline: "ventral-tip" (the lower sixth of the longest span of the axis
// that keeps the offset), "midline" (the whole span), "dorsal-tip" (the upper sixth). Throws
// naris::Error when no point of the axis keeps the offset.
ReleaseSet dissertation_groups(const InletShape& inlet, double offset, int count);
// A regular grid on the naris plane, `across` points along the long axis, spacing alike along
// the short one; points nearer the outline than `offset` are left out (group "grid").
ReleaseSet grid_release(const InletShape& inlet, int across, double offset);
// `count` points from a to b inclusive (group "line").
ReleaseSet line_release(const Vec3& a, const Vec3& b, int count);
// `count` points on the inlet, density ∝ the inflow u·n (group "flux-weighted"); the same
// `seed` gives the same points on every machine.
ReleaseSet flux_weighted_release(const HybridMesh& mesh, int patch, std::span<const Vec3> velocity,
                                 int count, std::uint64_t seed);
// A CSV file of x,y,z in millimetres, an optional fourth column naming the group; a header
// line is allowed.
ReleaseSet read_release_points(const std::string& path);

}  // namespace naris::particles
