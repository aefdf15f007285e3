#pragma once
// Cross-section planes of the airway (section 4.3.1): normal to the anterior–posterior axis at
// distances from the airway's most anterior point, or by point and normal. The axis runs from
// the inlet's centroid to the outlet's, or along an image axis the user names. Shared by
// `naris trace` (crossings) and `naris planes` (sections). Millimetres.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris {

struct SectionPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // mm
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  std::string label;      // "33.5 mm" or the p=…;n=… text
  double distance = 0.0;  // mm from the anterior tip along the axis (planes by distance)
  bool by_distance = false;
};

// "inlet-outlet" (default) or an image axis "x", "y", "z", "-x", "-y", "-z" (LPS).
struct SectionAxis {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();
  double tip = 0.0, end = 0.0;  // the extent of direction·x over the mesh's nodes (mm)
};
// Throws naris::Error for an unknown name, or inlet-outlet on a mesh without both patches.
SectionAxis section_axis(const HybridMesh& mesh, const std::string& name = "inlet-outlet");

// The area-weighted centroid of a patch (mm); throws naris::Error when it has no faces.
Eigen::Vector3d patch_centroid(const HybridMesh& mesh, int patch);

// Planes at `distances` along `axis` and planes given as "p=x,y,z;n=nx,ny,nz". Throws
// naris::Error for a distance beyond the airway's length, a malformed plane, or a plane that
// misses the mesh.
std::vector<SectionPlane> section_planes(const HybridMesh& mesh, const SectionAxis& axis,
                                         const std::vector<double>& distances,
                                         const std::vector<std::string>& planes);

// Named region patches (not inlet, outlet or wall) as the boxes of their faces (mm): where the
// mesh has an `olfactory` patch, the box it was carved by.
struct RegionBox {
  int patch = -1;
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  bool contains(const Eigen::Vector3d& x) const {
    return (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all();
  }
};
std::vector<RegionBox> region_boxes(const HybridMesh& mesh);
bool is_open_patch(const std::string& name);  // inlet or outlet

}  // namespace naris
