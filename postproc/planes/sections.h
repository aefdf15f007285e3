#pragma once
// Cross-sections of the flow solution (section 4.3.1, Table 4.3): the mesh cut by a plane with
// VTK's cutter, its connected pieces, and per piece the area, the outline's length (raw and
// smoothed at the voxel scale, outline.h), the hydraulic diameter 4A/P, the volume flux, the
// mean and maximum axial velocity, the maximum speed and the flux through named regions. The
// flux is that of the velocity the method conserves, the nodal velocity plus the cells'
// fine-scale velocity (solver/ns/subgrid_velocity.h); the nodal velocity's alone is kept too.
// Millimetres for geometry, SI for the flow.
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

#include <span>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "mesh/patches/section_planes.h"
#include "postproc/planes/outline.h"

namespace naris::airflow {
struct SolvedMesh;
}

namespace naris::planes {

struct Measures {
  double area = 0.0;                                   // mm²
  double perimeter = 0.0, raw_perimeter = 0.0;         // mm: smoothed, and the outline as meshed
  double hydraulic_diameter = 0.0;                     // mm: 4A/P on the smoothed perimeter
  double raw_hydraulic_diameter = 0.0;                 // mm: 4A/P on the raw perimeter
  double flux = 0.0;                                   // m³/s along the normal: u + u'
  double resolved_flux = 0.0;                          // m³/s: the nodal velocity u alone
  double mean_axial = 0.0;                             // m/s: flux / area (u + u')
  double max_axial = 0.0;                              // m/s: of u at the section's points
  double max_speed = 0.0;                              // m/s
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // mm
  std::vector<double> region_flux;  // m³/s (u + u') through each region box's part
};

struct Section {
  SectionPlane plane;
  std::vector<Measures> pieces;  // largest area first
  Measures whole;                // all pieces: sums and maxima (perimeters summed)
  // Triangles (mm) with point arrays velocity, speed, axial_velocity, secondary_velocity (m/s)
  // and cell arrays subgrid_velocity, subgrid_axial_velocity (m/s) and piece (1 = largest; 0:
  // slivers without area).
  vtkSmartPointer<vtkPolyData> surface;
  std::vector<Loop> outline;  // the wall's trace on the plane, as meshed
};

// The voxel spacing an MVE mesh was built on (the median hexahedron edge; without hexahedra,
// the median edge of the tetrahedra), mm.
double voxel_size(const HybridMesh& mesh);

// The fine-scale velocity of a solution per cell, m/s (solver/ns/subgrid_velocity.h).
std::vector<Eigen::Vector3d> subgrid_velocity(const airflow::SolvedMesh& solved);

class SectionCutter {
 public:
  // `velocity`: nodal, m/s; `subgrid`: per cell in the mesh's order (tetrahedra, pyramids,
  // hexahedra), m/s, or empty for none. `smoothing`: the Gaussian width for perimeters, mm.
  SectionCutter(const HybridMesh& mesh, std::span<const Eigen::Vector3d> velocity,
                std::span<const Eigen::Vector3d> subgrid, double smoothing);
  // Throws naris::Error when the plane does not cut the mesh.
  Section cut(const SectionPlane& plane, const std::vector<RegionBox>& regions = {}) const;
  // A boundary patch measured as a section (normal: its mean outward normal, reversed, so an
  // inlet's inflow is positive); the mass through a boundary is that of u alone.
  Measures patch(int patch) const;

 private:
  const HybridMesh& mesh_;
  std::span<const Eigen::Vector3d> velocity_;
  double smoothing_;
  vtkSmartPointer<vtkUnstructuredGrid> grid_;
};

// The speeds and velocities of a section's points as arrays on `surface` (in place), and the
// axial fine-scale velocity of its cells when it has subgrid_velocity.
void add_flow_arrays(vtkPolyData* surface, const Eigen::Vector3d& normal);
// Measures of one connected polygonal piece (triangles) with the arrays of add_flow_arrays.
// Its outline's loops are appended to `outline` when given.
Measures measure_piece(vtkPolyData* piece, double smoothing, const std::vector<RegionBox>& regions,
                       std::vector<Loop>* outline = nullptr);

}  // namespace naris::planes
