#include "io/write_vtk.h"

#include <vtkCellArray.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkCellData.h>
#include <vtkSTLWriter.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include "core/error.h"
#include "io/atomic_file.h"

namespace naris {
namespace {

vtkSmartPointer<vtkPoints> make_points(const HybridMesh& mesh) {
  auto coords = vtkSmartPointer<vtkDoubleArray>::New();
  coords->SetNumberOfComponents(3);
  coords->SetNumberOfTuples(static_cast<vtkIdType>(mesh.nodes.size()));
  double* out = coords->GetPointer(0);
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
    for (int a = 0; a < 3; ++a) out[3 * n + a] = mesh.nodes[n][a];
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(coords);
  return points;
}

// Builds a vtkCellArray from fixed-size cells without a per-cell call.
template <class Cells>
void append_cells(const Cells& cells, std::vector<vtkIdType>& offsets,
                  std::vector<vtkIdType>& connectivity) {
  for (const auto& c : cells) {
    for (NodeId n : c) connectivity.push_back(n);
    offsets.push_back(static_cast<vtkIdType>(connectivity.size()));
  }
}

vtkSmartPointer<vtkCellArray> make_cell_array(std::vector<vtkIdType>& offsets,
                                              std::vector<vtkIdType>& connectivity) {
  auto off = vtkSmartPointer<vtkIdTypeArray>::New();
  off->SetNumberOfTuples(static_cast<vtkIdType>(offsets.size()));
  std::copy(offsets.begin(), offsets.end(), off->GetPointer(0));
  auto con = vtkSmartPointer<vtkIdTypeArray>::New();
  con->SetNumberOfTuples(static_cast<vtkIdType>(connectivity.size()));
  std::copy(connectivity.begin(), connectivity.end(), con->GetPointer(0));
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  cells->SetData(off, con);
  return cells;
}

template <class Writer>
void run_writer(Writer* writer, const std::filesystem::path& path) {
  AtomicOutput out(path);
  writer->SetFileName(out.temp_path().c_str());
  if (writer->Write() != 1) fail("{}: VTK could not write the file", path.string());
  out.commit();
}

}  // namespace

void write_vtu(const HybridMesh& mesh, const std::filesystem::path& path,
               const CellFields& cell_fields) {
  std::vector<vtkIdType> offsets{0}, connectivity;
  offsets.reserve(mesh.cell_count() + 1);
  connectivity.reserve(4 * mesh.tets.size() + 5 * mesh.pyramids.size() + 8 * mesh.hexes.size());
  append_cells(mesh.tets, offsets, connectivity);
  append_cells(mesh.pyramids, offsets, connectivity);
  append_cells(mesh.hexes, offsets, connectivity);
  auto types = vtkSmartPointer<vtkUnsignedCharArray>::New();
  types->SetNumberOfTuples(static_cast<vtkIdType>(mesh.cell_count()));
  unsigned char* t = types->GetPointer(0);
  std::fill_n(t, mesh.tets.size(), static_cast<unsigned char>(VTK_TETRA));
  std::fill_n(t + mesh.tets.size(), mesh.pyramids.size(), static_cast<unsigned char>(VTK_PYRAMID));
  std::fill_n(t + mesh.tets.size() + mesh.pyramids.size(), mesh.hexes.size(),
              static_cast<unsigned char>(VTK_HEXAHEDRON));

  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->SetPoints(make_points(mesh));
  grid->SetCells(types, make_cell_array(offsets, connectivity));
  for (const auto& [name, values] : cell_fields) {
    if (values.size() != mesh.cell_count())
      fail("internal: cell field '{}' has {} values for {} cells", name, values.size(),
           mesh.cell_count());
    auto a = vtkSmartPointer<vtkDoubleArray>::New();
    a->SetName(name.c_str());
    a->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
    std::copy(values.begin(), values.end(), a->GetPointer(0));
    grid->GetCellData()->AddArray(a);
  }
  auto writer = vtkSmartPointer<vtkXMLUnstructuredGridWriter>::New();
  writer->SetInputData(grid);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToNone();
  writer->SetHeaderTypeToUInt64();
  run_writer(writer.Get(), path);
}

namespace {
vtkSmartPointer<vtkPolyData> boundary_polydata(const HybridMesh& mesh, bool triangulate) {
  std::vector<vtkIdType> offsets{0}, connectivity;
  auto patch = vtkSmartPointer<vtkIntArray>::New();
  patch->SetName("patch");
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f) {
    for (NodeId n : mesh.boundary_tris[f]) connectivity.push_back(n);
    offsets.push_back(static_cast<vtkIdType>(connectivity.size()));
    patch->InsertNextValue(mesh.boundary_tri_patch[f]);
  }
  for (std::size_t f = 0; f < mesh.boundary_quads.size(); ++f) {
    const auto& q = mesh.boundary_quads[f];
    if (triangulate) {
      for (const auto& tri : {std::array<NodeId, 3>{q[0], q[1], q[2]}, {q[0], q[2], q[3]}}) {
        for (NodeId n : tri) connectivity.push_back(n);
        offsets.push_back(static_cast<vtkIdType>(connectivity.size()));
        patch->InsertNextValue(mesh.boundary_quad_patch[f]);
      }
    } else {
      for (NodeId n : q) connectivity.push_back(n);
      offsets.push_back(static_cast<vtkIdType>(connectivity.size()));
      patch->InsertNextValue(mesh.boundary_quad_patch[f]);
    }
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(make_points(mesh));
  poly->SetPolys(make_cell_array(offsets, connectivity));
  poly->GetCellData()->AddArray(patch);
  return poly;
}
}  // namespace

void write_boundary_vtp(const HybridMesh& mesh, const std::filesystem::path& path) {
  auto writer = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
  writer->SetInputData(boundary_polydata(mesh, false));
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToNone();
  run_writer(writer.Get(), path);
}

void write_stl(const HybridMesh& mesh, const std::filesystem::path& path) {
  auto writer = vtkSmartPointer<vtkSTLWriter>::New();
  writer->SetInputData(boundary_polydata(mesh, true));
  writer->SetFileTypeToBinary();
  run_writer(writer.Get(), path);
}

}  // namespace naris
