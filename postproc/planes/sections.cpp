#include "postproc/planes/sections.h"

#include <vtkBox.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCleanPolyData.h>
#include <vtkClipPolyData.h>
#include <vtkCutter.h>
#include <vtkDoubleArray.h>
#include <vtkFeatureEdges.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkIntegrateAttributes.h>
#include <vtkNew.h>
#include <vtkPlane.h>
#include <vtkPointData.h>
#include <vtkPolyDataConnectivityFilter.h>
#include <vtkStripper.h>

#include <algorithm>
#include <numeric>

#include "core/error.h"
#include "core/units.h"
#include "solver/airflow/solution_file.h"
#include "solver/ns/subgrid_velocity.h"

namespace naris::planes {
namespace {

vtkSmartPointer<vtkDoubleArray> vector_array(const char* name, vtkIdType n) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name);
  a->SetNumberOfComponents(3);
  a->SetNumberOfTuples(n);
  return a;
}

vtkSmartPointer<vtkDoubleArray> scalar_array(const char* name, vtkIdType n) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name);
  a->SetNumberOfTuples(n);
  return a;
}

// The integrals of the point array axial_velocity and the cell array subgrid_axial_velocity
// (0 when absent) from vtkIntegrateAttributes's output.
double integrated_axial(vtkUnstructuredGrid* sums) {
  return sums->GetPointData()->GetArray("axial_velocity")->GetTuple1(0);
}
double integrated_subgrid(vtkUnstructuredGrid* sums) {
  vtkDataArray* a = sums->GetCellData()->GetArray("subgrid_axial_velocity");
  return a ? a->GetTuple1(0) : 0.0;
}

// The flux of u + u' through a polygonal dataset, mm²·m/s (0 when it is empty).
double integrate_flux(vtkPolyData* data) {
  if (data->GetNumberOfCells() == 0) return 0.0;
  vtkNew<vtkIntegrateAttributes> integral;
  integral->SetInputData(data);
  integral->Update();
  return integrated_axial(integral->GetOutput()) + integrated_subgrid(integral->GetOutput());
}

std::vector<Loop> outline_loops(vtkPolyData* piece) {
  vtkNew<vtkFeatureEdges> edges;
  edges->SetInputData(piece);
  edges->BoundaryEdgesOn();
  edges->FeatureEdgesOff();
  edges->ManifoldEdgesOff();
  edges->NonManifoldEdgesOff();
  edges->ColoringOff();
  vtkNew<vtkStripper> strip;
  strip->SetInputConnection(edges->GetOutputPort());
  strip->JoinContiguousSegmentsOn();
  strip->Update();
  vtkPolyData* lines = strip->GetOutput();
  std::vector<Loop> loops;
  vtkNew<vtkIdList> ids;
  vtkCellArray* cells = lines->GetLines();
  cells->InitTraversal();
  while (cells->GetNextCell(ids)) {
    Loop loop;
    vtkIdType n = ids->GetNumberOfIds();
    if (n > 1 && ids->GetId(0) == ids->GetId(n - 1)) --n;  // closed: the first point repeats
    for (vtkIdType k = 0; k < n; ++k) {
      double x[3];
      lines->GetPoint(ids->GetId(k), x);
      loop.emplace_back(x[0], x[1], x[2]);
    }
    if (loop.size() >= 2) loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace

double voxel_size(const HybridMesh& mesh) {
  std::vector<double> edges;
  const std::size_t stride_hex = std::max<std::size_t>(1, mesh.hexes.size() / 2000);
  for (std::size_t c = 0; c < mesh.hexes.size(); c += stride_hex) {
    const auto& h = mesh.hexes[c];
    edges.push_back((mesh.nodes[h[1]] - mesh.nodes[h[0]]).norm());
  }
  if (edges.empty()) {
    const std::size_t stride = std::max<std::size_t>(1, mesh.tets.size() / 2000);
    for (std::size_t c = 0; c < mesh.tets.size(); c += stride) {
      const auto& t = mesh.tets[c];
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
          edges.push_back((mesh.nodes[t[b]] - mesh.nodes[t[a]]).norm());
    }
  }
  if (edges.empty()) fail("the mesh has no cells");
  std::nth_element(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(edges.size() / 2),
                   edges.end());
  return edges[edges.size() / 2];
}

std::vector<Eigen::Vector3d> subgrid_velocity(const airflow::SolvedMesh& solved) {
  const airflow::SolutionState& st = solved.state;
  std::vector<Eigen::Vector3d> sub =
      ns::subgrid_velocity(solved.mesh, st.field, 1.0 / st.reynolds, st.d_in_mm);
  for (Eigen::Vector3d& u : sub) u *= st.u_in;
  return sub;
}

void add_flow_arrays(vtkPolyData* surface, const Eigen::Vector3d& normal) {
  vtkDataArray* velocity = surface->GetPointData()->GetArray("velocity");
  if (!velocity) fail("the section has no velocity");
  const vtkIdType n = surface->GetNumberOfPoints();
  auto speed = scalar_array("speed", n), axial = scalar_array("axial_velocity", n);
  auto secondary = vector_array("secondary_velocity", n), position = vector_array("position", n);
  for (vtkIdType i = 0; i < n; ++i) {
    double u[3], x[3];
    velocity->GetTuple(i, u);
    surface->GetPoint(i, x);
    const Eigen::Vector3d v(u[0], u[1], u[2]);
    const double a = v.dot(normal);
    const Eigen::Vector3d s = v - a * normal;
    speed->SetValue(i, v.norm());
    axial->SetValue(i, a);
    secondary->SetTuple3(i, s[0], s[1], s[2]);
    position->SetTuple3(i, x[0], x[1], x[2]);
  }
  surface->GetPointData()->AddArray(speed);
  surface->GetPointData()->AddArray(axial);
  surface->GetPointData()->AddArray(secondary);
  surface->GetPointData()->AddArray(position);
  surface->GetPointData()->SetActiveScalars("speed");
  vtkDataArray* subgrid = surface->GetCellData()->GetArray("subgrid_velocity");
  if (!subgrid) return;
  const vtkIdType cells = surface->GetNumberOfCells();
  auto subgrid_axial = scalar_array("subgrid_axial_velocity", cells);
  for (vtkIdType c = 0; c < cells; ++c) {
    double u[3];
    subgrid->GetTuple(c, u);
    subgrid_axial->SetValue(c, Eigen::Vector3d(u[0], u[1], u[2]).dot(normal));
  }
  surface->GetCellData()->AddArray(subgrid_axial);
}

Measures measure_piece(vtkPolyData* piece, double smoothing, const std::vector<RegionBox>& regions,
                       std::vector<Loop>* outline) {
  Measures m;
  vtkNew<vtkIntegrateAttributes> integral;
  integral->SetInputData(piece);
  integral->Update();
  vtkUnstructuredGrid* sums = integral->GetOutput();
  if (auto* a = sums->GetCellData()->GetArray("Area")) m.area = a->GetTuple1(0);
  m.region_flux.assign(regions.size(), 0.0);
  if (!(m.area > 0.0)) return m;
  const double axial_sum = integrated_axial(sums);
  m.resolved_flux = axial_sum * kMm2;
  m.flux = (axial_sum + integrated_subgrid(sums)) * kMm2;
  m.mean_axial = m.flux / (m.area * kMm2);
  vtkDataArray* x = sums->GetPointData()->GetArray("position");  // ∫x dA
  m.centroid =
      Eigen::Vector3d(x->GetComponent(0, 0), x->GetComponent(0, 1), x->GetComponent(0, 2)) / m.area;
  vtkDataArray* speed = piece->GetPointData()->GetArray("speed");
  vtkDataArray* axial = piece->GetPointData()->GetArray("axial_velocity");
  m.max_axial = -1e300;
  for (vtkIdType i = 0; i < piece->GetNumberOfPoints(); ++i) {
    m.max_speed = std::max(m.max_speed, speed->GetTuple1(i));
    m.max_axial = std::max(m.max_axial, axial->GetTuple1(i));
  }
  for (Loop& loop : outline_loops(piece)) {
    m.raw_perimeter += loop_length(loop);
    m.perimeter += smoothed_loop_length(loop, smoothing);
    if (outline) outline->push_back(std::move(loop));
  }
  m.hydraulic_diameter = m.perimeter > 0.0 ? 4.0 * m.area / m.perimeter : 0.0;
  m.raw_hydraulic_diameter = m.raw_perimeter > 0.0 ? 4.0 * m.area / m.raw_perimeter : 0.0;
  for (const RegionBox& r : regions) {
    vtkNew<vtkBox> box;
    box->SetBounds(r.lo[0], r.hi[0], r.lo[1], r.hi[1], r.lo[2], r.hi[2]);
    vtkNew<vtkClipPolyData> clip;
    clip->SetInputData(piece);
    clip->SetClipFunction(box);
    clip->InsideOutOn();
    clip->Update();
    m.region_flux[static_cast<std::size_t>(&r - regions.data())] =
        integrate_flux(clip->GetOutput()) * kMm2;
  }
  return m;
}

SectionCutter::SectionCutter(const HybridMesh& mesh, std::span<const Eigen::Vector3d> velocity,
                             std::span<const Eigen::Vector3d> subgrid, double smoothing)
    : mesh_(mesh),
      velocity_(velocity),
      smoothing_(smoothing),
      grid_(vtkSmartPointer<vtkUnstructuredGrid>::New()) {
  if (velocity.size() != mesh.nodes.size())
    fail("the velocity has {} nodes, the mesh {}", velocity.size(), mesh.nodes.size());
  if (!subgrid.empty() && subgrid.size() != mesh.cell_count())
    fail("the fine-scale velocity has {} cells, the mesh {}", subgrid.size(), mesh.cell_count());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.nodes.size()));
  auto u = vector_array("velocity", static_cast<vtkIdType>(mesh.nodes.size()));
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    const auto id = static_cast<vtkIdType>(i);
    points->SetPoint(id, mesh.nodes[i].data());
    u->SetTuple(id, velocity[i].data());
  }
  grid_->SetPoints(points);
  grid_->GetPointData()->AddArray(u);
  grid_->AllocateExact(static_cast<vtkIdType>(mesh.cell_count()),
                       static_cast<vtkIdType>(4 * mesh.tets.size() + 5 * mesh.pyramids.size() +
                                              8 * mesh.hexes.size()));
  auto insert = [&](int type, const auto& cells) {
    vtkIdType ids[8];
    for (const auto& c : cells) {
      for (std::size_t k = 0; k < c.size(); ++k) ids[k] = c[k];
      grid_->InsertNextCell(type, static_cast<vtkIdType>(c.size()), ids);
    }
  };
  insert(VTK_TETRA, mesh.tets);
  insert(VTK_PYRAMID, mesh.pyramids);
  insert(VTK_HEXAHEDRON, mesh.hexes);
  if (subgrid.empty()) return;
  auto cell_velocity = vector_array("subgrid_velocity", static_cast<vtkIdType>(subgrid.size()));
  for (std::size_t c = 0; c < subgrid.size(); ++c)
    cell_velocity->SetTuple(static_cast<vtkIdType>(c), subgrid[c].data());
  grid_->GetCellData()->AddArray(cell_velocity);
}

Section SectionCutter::cut(const SectionPlane& plane, const std::vector<RegionBox>& regions) const {
  Section s;
  s.plane = plane;
  vtkNew<vtkPlane> function;
  function->SetOrigin(plane.point.data());
  function->SetNormal(plane.normal.data());
  vtkNew<vtkCutter> cutter;
  cutter->SetInputData(grid_);
  cutter->SetCutFunction(function);
  cutter->GenerateTrianglesOn();
  vtkNew<vtkCleanPolyData> clean;  // one point where cells share an edge crossing
  clean->SetInputConnection(cutter->GetOutputPort());
  clean->PointMergingOn();
  clean->ToleranceIsAbsoluteOn();
  clean->SetAbsoluteTolerance(0.0);
  clean->ConvertPolysToLinesOff();  // a plane through a pocket's tip leaves slivers as polygons
  clean->ConvertLinesToPointsOff();
  clean->Update();
  vtkSmartPointer<vtkPolyData> surface = clean->GetOutput();
  if (surface->GetNumberOfCells() == 0) fail("plane {} does not cut the airway", plane.label);
  if (grid_->GetCellData()->GetArray("subgrid_velocity") &&
      !surface->GetCellData()->GetArray("subgrid_velocity"))
    fail("VTK's cutter dropped the fine-scale velocity of plane {}", plane.label);
  add_flow_arrays(surface, plane.normal);

  vtkNew<vtkPolyDataConnectivityFilter> all;
  all->SetInputData(surface);
  all->SetExtractionModeToAllRegions();
  all->ColorRegionsOn();
  all->Update();
  const int count = all->GetNumberOfExtractedRegions();
  std::vector<Measures> pieces;
  for (int r = 0; r < count; ++r) {
    vtkNew<vtkPolyDataConnectivityFilter> one;
    one->SetInputData(surface);
    one->SetExtractionModeToSpecifiedRegions();
    one->AddSpecifiedRegion(r);
    one->Update();
    pieces.push_back(measure_piece(one->GetOutput(), smoothing_, regions, &s.outline));
  }
  std::vector<int> order(static_cast<std::size_t>(count));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return pieces[static_cast<std::size_t>(a)].area > pieces[static_cast<std::size_t>(b)].area;
  });
  // Pieces without area (a plane touching a pocket at a node or an edge) get piece 0 and no row.
  std::vector<int> rank(static_cast<std::size_t>(count), 0);
  for (int k = 0; k < count; ++k) {
    const Measures& m = pieces[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])];
    if (!(m.area > 0.0)) continue;
    s.pieces.push_back(m);
    rank[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])] =
        static_cast<int>(s.pieces.size());
  }
  if (s.pieces.empty()) fail("plane {} touches the airway without cutting it", plane.label);
  // The piece of each cell, on the surface as written.
  vtkPolyData* colored = all->GetOutput();
  vtkDataArray* region = colored->GetPointData()->GetArray("RegionId");  // per point
  if (!region) fail("VTK's connectivity filter gave no regions");
  vtkNew<vtkIntArray> piece;
  piece->SetName("piece");
  piece->SetNumberOfTuples(colored->GetNumberOfCells());
  for (vtkIdType c = 0; c < colored->GetNumberOfCells(); ++c)
    piece->SetValue(
        c, rank[static_cast<std::size_t>(region->GetTuple1(colored->GetCell(c)->GetPointId(0)))]);
  colored->GetCellData()->RemoveArray("RegionId");
  colored->GetPointData()->RemoveArray("RegionId");
  colored->GetPointData()->RemoveArray("position");
  colored->GetCellData()->AddArray(piece);
  colored->GetPointData()->SetActiveScalars("speed");
  s.surface = vtkSmartPointer<vtkPolyData>::New();
  s.surface->ShallowCopy(colored);

  Measures& w = s.whole;
  w.max_axial = -1e300;
  w.region_flux.assign(regions.size(), 0.0);
  for (const Measures& m : s.pieces) {
    w.area += m.area, w.perimeter += m.perimeter, w.raw_perimeter += m.raw_perimeter;
    w.flux += m.flux;
    w.resolved_flux += m.resolved_flux;
    w.centroid += m.area * m.centroid;
    w.max_axial = std::max(w.max_axial, m.max_axial);
    w.max_speed = std::max(w.max_speed, m.max_speed);
    for (std::size_t i = 0; i < regions.size(); ++i) w.region_flux[i] += m.region_flux[i];
  }
  w.centroid /= w.area;
  w.mean_axial = w.flux / (w.area * kMm2);
  w.hydraulic_diameter = 4.0 * w.area / w.perimeter;
  w.raw_hydraulic_diameter = 4.0 * w.area / w.raw_perimeter;
  return s;
}

Measures SectionCutter::patch(int patch) const {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> triangles;
  auto u = vtkSmartPointer<vtkDoubleArray>::New();
  u->SetName("velocity");
  u->SetNumberOfComponents(3);
  std::vector<vtkIdType> local(mesh_.nodes.size(), -1);
  Eigen::Vector3d vector_area = Eigen::Vector3d::Zero();
  auto id = [&](NodeId v) {
    vtkIdType& l = local[static_cast<std::size_t>(v)];
    if (l < 0) {
      l = points->InsertNextPoint(mesh_.nodes[v].data());
      u->InsertNextTuple(velocity_[static_cast<std::size_t>(v)].data());
    }
    return l;
  };
  for_each_boundary_face(mesh_, [&](std::span<const NodeId> ids, std::int32_t p) {
    if (p != patch) return;
    for (std::size_t k = 1; k + 1 < ids.size(); ++k) {
      const vtkIdType t[3] = {id(ids[0]), id(ids[k]), id(ids[k + 1])};
      triangles->InsertNextCell(3, t);
      vector_area += 0.5 * (mesh_.nodes[ids[k]] - mesh_.nodes[ids[0]])
                               .cross(mesh_.nodes[ids[k + 1]] - mesh_.nodes[ids[0]]);
    }
  });
  if (triangles->GetNumberOfCells() == 0) fail("patch {} has no faces", patch);
  vtkNew<vtkPolyData> surface;
  surface->SetPoints(points);
  surface->SetPolys(triangles);
  surface->GetPointData()->AddArray(u);
  const Eigen::Vector3d inward = -vector_area.normalized();
  add_flow_arrays(surface, inward);
  return measure_piece(surface, smoothing_, {});
}

}  // namespace naris::planes
