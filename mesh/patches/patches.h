#pragma once
// Boundary patches: the inlet and outlet as cut planes, named regions carved out of the wall,
// and the per-patch report (area; perimeter and hydraulic diameter 4A/P).
#include <Eigen/Dense>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "mesh/mve/mve.h"

namespace naris {

// "i=20", "j=19.5", "k=0" (voxel-index planes) or "p=x,y,z;n=nx,ny,nz" (millimetres).
struct CutPlane {
  std::string text;
  bool index_plane = false;
  int axis = 0;                                       // index planes
  double index = 0.0;                                 // index planes
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // physical planes
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // physical planes, unit
};
CutPlane parse_cut_plane(const std::string& text);

// "name:box=x0,y0,z0,x1,y1,z1" or "name:sphere=x,y,z,r" (millimetres).
struct Region {
  std::string name;
  bool sphere = false;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0.0;
  bool contains(const Eigen::Vector3d& x) const;
};
Region parse_region(const std::string& text);

// A named cut: the patch its faces become.
struct Cut {
  std::string patch;
  CutPlane plane;
};

// Prepares the mesher for the cuts: planes along an image axis become crop-box sides, oblique
// planes become the mesher's clip planes. Each keeps the side that holds the other planes (an
// inlet and an outlet keep what lies between them); a single plane keeps the side towards the
// object's centroid.
struct PreparedCuts {
  std::vector<Cut> oblique;  // to be labelled after meshing
  Eigen::Vector3d centroid_index = Eigen::Vector3d::Zero();
};
PreparedCuts prepare_cuts(const mve::FieldSource& field, const std::vector<Cut>& cuts,
                          mve::MveOptions& options);

// After meshing: labels faces on oblique cut planes, checks that every cut produced a patch,
// and carves region patches out of `from_patch`.
void finish_patches(HybridMesh& mesh, const mve::FieldSource& field, const std::vector<Cut>& cuts,
                    const PreparedCuts& prepared, const std::vector<Region>& regions,
                    const std::string& from_patch);

struct PatchReport {
  std::string name;
  std::size_t faces = 0;
  double area = 0.0;       // mm²
  double perimeter = 0.0;  // mm: length of the patch's own boundary edges
  double hydraulic_diameter() const { return perimeter > 0.0 ? 4.0 * area / perimeter : 0.0; }
};
std::vector<PatchReport> patch_report(const HybridMesh& mesh);

// The connected pieces of one patch (faces that share a node), such as the two nares of an
// inlet cut across both: per boundary face (in for_each_boundary_face's order) the index of its
// opening, −1 off the patch; and each opening's area and centroid (mesh units), largest first.
struct PatchOpenings {
  std::vector<int> of_face;
  std::vector<double> area;
  std::vector<Eigen::Vector3d> centroid;
};
PatchOpenings patch_openings(const HybridMesh& mesh, int patch);

}  // namespace naris
