#include "mesh/patches/section_planes.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "core/error.h"
#include "mesh/patches/patches.h"

namespace naris {

bool is_open_patch(const std::string& name) {
  return name == "inlet" || name == "outlet";
}

Eigen::Vector3d patch_centroid(const HybridMesh& mesh, int patch) {
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  double area = 0.0;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> ids, std::int32_t p) {
    if (p != patch) return;
    for (std::size_t k = 1; k + 1 < ids.size(); ++k) {
      const Eigen::Vector3d &a = mesh.nodes[ids[0]], &b = mesh.nodes[ids[k]],
                            &c = mesh.nodes[ids[k + 1]];
      const double t = 0.5 * (b - a).cross(c - a).norm();
      first += t * (a + b + c) / 3.0;
      area += t;
    }
  });
  if (!(area > 0.0)) fail("patch {} has no faces", patch);
  return first / area;
}

SectionAxis section_axis(const HybridMesh& mesh, const std::string& name) {
  SectionAxis axis;
  if (name == "inlet-outlet") {
    const int inlet = mesh.patch_id("inlet"), outlet = mesh.patch_id("outlet");
    if (inlet < 0 || outlet < 0)
      fail(
          "planes by distance need the mesh's inlet and outlet patches (the anterior–posterior "
          "axis), or an image axis (axis: x, y or z)");
    const Eigen::Vector3d d = patch_centroid(mesh, outlet) - patch_centroid(mesh, inlet);
    if (!(d.norm() > 0.0)) fail("the inlet and outlet have the same centroid: no axis");
    axis.direction = d.normalized();
  } else {
    const bool minus = !name.empty() && name[0] == '-';
    const std::string a = minus ? name.substr(1) : name;
    if (a != "x" && a != "y" && a != "z")
      fail("axis '{}' not understood: inlet-outlet, x, y, z, -x, -y or -z", name);
    axis.direction = Eigen::Vector3d::Unit(a[0] - 'x') * (minus ? -1.0 : 1.0);
  }
  axis.tip = std::numeric_limits<double>::infinity();
  axis.end = -axis.tip;
  for (const Eigen::Vector3d& x : mesh.nodes) {
    const double s = axis.direction.dot(x);
    axis.tip = std::min(axis.tip, s), axis.end = std::max(axis.end, s);
  }
  return axis;
}

std::vector<SectionPlane> section_planes(const HybridMesh& mesh, const SectionAxis& axis,
                                         const std::vector<double>& distances,
                                         const std::vector<std::string>& planes) {
  std::vector<SectionPlane> out;
  const double length = axis.end - axis.tip;
  for (double s : distances) {
    if (!(s > 0.0 && s < length))
      fail(
          "plane at {:g} mm: the airway runs {:.1f} mm along its axis; give a distance in (0, "
          "{:.1f})",
          s, length, length);
    out.push_back(
        {(axis.tip + s) * axis.direction, axis.direction, fmt::format("{:g} mm", s), s, true});
  }
  for (const std::string& text : planes) {
    const CutPlane c = parse_cut_plane(text);
    if (c.index_plane) fail("plane '{}': give a plane as p=x,y,z;n=nx,ny,nz (mm)", text);
    out.push_back({c.point, c.normal, text, 0.0, false});
  }
  for (const SectionPlane& p : out) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Eigen::Vector3d& x : mesh.nodes) {
      const double s = p.normal.dot(x - p.point);
      lo = std::min(lo, s), hi = std::max(hi, s);
    }
    if (!(lo < 0.0 && hi > 0.0)) fail("plane {} misses the airway", p.label);
  }
  return out;
}

std::vector<RegionBox> region_boxes(const HybridMesh& mesh) {
  std::vector<RegionBox> boxes;
  for (std::size_t p = 0; p < mesh.patch_names.size(); ++p) {
    if (is_open_patch(mesh.patch_names[p]) || mesh.patch_names[p] == "wall") continue;
    RegionBox box{static_cast<int>(p), Eigen::Vector3d::Constant(1e300),
                  Eigen::Vector3d::Constant(-1e300)};
    for_each_boundary_face(mesh, [&](std::span<const NodeId> ids, std::int32_t q) {
      if (q != box.patch) return;
      for (NodeId v : ids)
        box.lo = box.lo.cwiseMin(mesh.nodes[v]), box.hi = box.hi.cwiseMax(mesh.nodes[v]);
    });
    if (box.lo[0] <= box.hi[0]) boxes.push_back(box);
  }
  return boxes;
}

}  // namespace naris
