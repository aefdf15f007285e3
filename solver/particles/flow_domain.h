#pragma once
// What a particle tracker needs of a flow: the fluid velocity anywhere, and the straight
// passage between two points with the first boundary it meets. The FE field on the hybrid mesh
// implements it (mesh_flow.h); the tests add analytic fields.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace naris::particles {

using Vec3 = Eigen::Vector3d;

// Where a walk along a segment a → b ended.
struct Passage {
  bool left = false;  // the segment met the boundary (or, with a radius, came within it of a wall)
  double t = 1.0;     // where along the segment, 0 … 1
  int patch = -1;     // the boundary patch met
  Vec3 normal = Vec3::Zero();  // outward unit normal of the face met
  int cell_tests = 0;          // cells visited
  bool stuck = false;          // the walk circled along a face or an edge (left, patch −1)
};

class FlowDomain {
 public:
  virtual ~FlowDomain() = default;
  // Fluid velocity (m/s) at x (m). `cell` is a cell holding `from`, a point of the domain; the
  // lookup walks from there and leaves in `cell` the cell it ended in. A point beyond the
  // boundary gets the velocity extrapolated from the boundary cell the walk left through.
  virtual Vec3 velocity(const Vec3& from, int& cell, const Vec3& x) const = 0;
  // Walks from a (in `cell`) straight to b; stops at the first boundary face, or, with a radius,
  // where the segment crosses a wall face's plane moved inwards by `radius` (in the cells it
  // visits; open patches have no wall). On return `cell` holds the end of the passage.
  virtual Passage pass(const Vec3& a, const Vec3& b, int& cell, double radius) const = 0;
  // A length that resolves the field near `cell` (m): a step moves at most a fraction of it.
  virtual double cell_size(int cell) const = 0;
  // The cell holding x, or -1 when x is outside.
  virtual int locate(const Vec3& x) const = 0;
  virtual const std::vector<std::string>& patch_names() const = 0;
};

}  // namespace naris::particles
