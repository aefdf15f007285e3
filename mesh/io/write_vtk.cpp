#include "mesh/io/write_vtk.h"

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLWriter.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cstdio>
#include <memory>

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris {
namespace {

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

void check_field_sizes(const HybridMesh& mesh, const CellFields& cell_fields,
                       const PointFields& point_fields) {
  for (const auto& [name, field] : cell_fields)
    if (field.components < 1 ||
        field.values.size() != static_cast<std::size_t>(field.components) * mesh.cell_count())
      fail("internal: cell field '{}' has {} values of {} components for {} cells", name,
           field.values.size(), field.components, mesh.cell_count());
  for (const auto& [name, field] : point_fields)
    if (field.values.size() != static_cast<std::size_t>(field.components) * mesh.nodes.size())
      fail("internal: point field '{}' has {} values for {} nodes", name, field.values.size(),
           mesh.nodes.size());
}

template <class Writer>
void run_writer(Writer* writer, const std::filesystem::path& path) {
  AtomicOutput out(path);
  writer->SetFileName(out.temp_path().c_str());
  if (writer->Write() != 1) fail("{}: VTK could not write the file", path.string());
  out.commit();
}

}  // namespace

// The volume mesh is the largest file naris writes, so it is written here directly from the
// mesh arrays as VTK XML with raw appended data (VTK's own writer copies every array first and
// is much slower; docs/results/solver-choices.md). The tests read it back with VTK's reader.
void write_vtu(const HybridMesh& mesh, const std::filesystem::path& path,
               const CellFields& cell_fields, const PointFields& point_fields) {
  check_field_sizes(mesh, cell_fields, point_fields);
  const std::size_t cells = mesh.cell_count();
  const std::uint64_t points_bytes = 3 * sizeof(double) * mesh.nodes.size();
  const std::uint64_t conn_bytes =
      sizeof(NodeId) * (4 * mesh.tets.size() + 5 * mesh.pyramids.size() + 8 * mesh.hexes.size());
  const std::uint64_t offsets_bytes = sizeof(std::int64_t) * cells;
  const std::uint64_t types_bytes = cells;

  std::string xml = fmt::format(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n <UnstructuredGrid>\n  <Piece "
      "NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
      mesh.nodes.size(), cells);
  std::uint64_t offset = 0;
  auto array = [&](const char* type, const std::string& name, int components, std::uint64_t bytes) {
    xml += fmt::format(
        "    <DataArray type=\"{}\"{} NumberOfComponents=\"{}\" format=\"appended\" "
        "offset=\"{}\"/>\n",
        type, name.empty() ? "" : " Name=\"" + name + "\"", components, offset);
    offset += sizeof(std::uint64_t) + bytes;
  };
  xml += "   <Points>\n";
  array("Float64", "", 3, points_bytes);
  xml += "   </Points>\n   <Cells>\n";
  array("Int32", "connectivity", 1, conn_bytes);
  array("Int64", "offsets", 1, offsets_bytes);
  array("UInt8", "types", 1, types_bytes);
  xml += "   </Cells>\n";
  if (!cell_fields.empty()) {
    xml += "   <CellData>\n";
    for (const auto& [name, field] : cell_fields)
      array("Float32", name, field.components, sizeof(float) * field.values.size());
    xml += "   </CellData>\n";
  }
  if (!point_fields.empty()) {
    xml += "   <PointData>\n";
    for (const auto& [name, field] : point_fields)
      array("Float32", name, field.components, sizeof(float) * field.values.size());
    xml += "   </PointData>\n";
  }
  xml += "  </Piece>\n </UnstructuredGrid>\n <AppendedData encoding=\"raw\">\n_";

  AtomicOutput out(path);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(out.temp_path().c_str(), "wb"),
                                                       &std::fclose);
  if (!file) fail("{}: cannot open for writing", path.string());
  auto put = [&](const void* data, std::size_t bytes) {
    if (bytes && std::fwrite(data, 1, bytes, file.get()) != bytes)
      fail("{}: write failed (disk full?)", path.string());
  };
  auto header = [&](std::uint64_t bytes) { put(&bytes, sizeof bytes); };
  put(xml.data(), xml.size());
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
  header(points_bytes);
  put(mesh.nodes.data(), points_bytes);
  header(conn_bytes);
  put(mesh.tets.data(), sizeof(NodeId) * 4 * mesh.tets.size());
  put(mesh.pyramids.data(), sizeof(NodeId) * 5 * mesh.pyramids.size());
  put(mesh.hexes.data(), sizeof(NodeId) * 8 * mesh.hexes.size());
  // Offsets and types are made in blocks rather than held whole.
  constexpr std::size_t kBlock = 1 << 16;
  std::vector<std::int64_t> offsets;
  std::vector<std::uint8_t> types;
  offsets.reserve(kBlock);
  types.reserve(kBlock);
  header(offsets_bytes);
  std::int64_t end = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    end += c < mesh.tets.size() ? 4 : c < mesh.tets.size() + mesh.pyramids.size() ? 5 : 8;
    offsets.push_back(end);
    if (offsets.size() == kBlock || c + 1 == cells) {
      put(offsets.data(), offsets.size() * sizeof(std::int64_t));
      offsets.clear();
    }
  }
  header(types_bytes);
  for (std::size_t c = 0; c < cells; ++c) {
    types.push_back(c < mesh.tets.size()                          ? VTK_TETRA
                    : c < mesh.tets.size() + mesh.pyramids.size() ? VTK_PYRAMID
                                                                  : VTK_HEXAHEDRON);
    if (types.size() == kBlock || c + 1 == cells) {
      put(types.data(), types.size());
      types.clear();
    }
  }
  std::vector<float> block;
  for (const auto* fields : {&cell_fields, &point_fields})
    for (const auto& [name, field] : *fields) {
      header(sizeof(float) * field.values.size());
      for (std::size_t c = 0; c < field.values.size(); c += kBlock) {
        block.assign(field.values.begin() + static_cast<std::ptrdiff_t>(c),
                     field.values.begin() +
                         static_cast<std::ptrdiff_t>(std::min(field.values.size(), c + kBlock)));
        put(block.data(), block.size() * sizeof(float));
      }
    }
  const std::string tail = "\n </AppendedData>\n</VTKFile>\n";
  put(tail.data(), tail.size());
  if (std::fflush(file.get()) != 0) fail("{}: write failed (disk full?)", path.string());
  file.reset();
  out.commit();
}

std::filesystem::path pvtu_piece_path(const std::filesystem::path& path, int piece) {
  return path.parent_path() / fmt::format("{}_{}.vtu", path.stem().string(), piece);
}

void write_pvtu_piece(const HybridMesh& mesh, const std::filesystem::path& path, int piece,
                      int pieces, const CellPredicate& owned, const CellFields& cell_fields,
                      const PointFields& point_fields) {
  check_field_sizes(mesh, cell_fields, point_fields);
  // The piece as a mesh of its own (nodes renumbered in their global order) and, for every
  // piece node and cell, where its values are in the whole mesh's fields.
  HybridMesh part;
  std::vector<NodeId> local(mesh.nodes.size(), -1);
  std::vector<std::size_t> cells;
  std::size_t c = 0;
  auto take = [&](const auto& from, auto& to) {
    for (const auto& cell : from) {
      if (owned(std::span<const NodeId>(cell))) {
        cells.push_back(c);
        to.push_back(cell);
        for (NodeId n : cell) local[static_cast<std::size_t>(n)] = 0;
      }
      ++c;
    }
  };
  take(mesh.tets, part.tets);
  take(mesh.pyramids, part.pyramids);
  take(mesh.hexes, part.hexes);
  std::vector<std::size_t> global;
  for (std::size_t n = 0; n < local.size(); ++n)
    if (local[n] == 0) {
      local[n] = static_cast<NodeId>(global.size());
      global.push_back(n);
      part.nodes.push_back(mesh.nodes[n]);
    }
  auto renumber = [&](auto& cells_of_type) {
    for (auto& cell : cells_of_type)
      for (NodeId& n : cell) n = local[static_cast<std::size_t>(n)];
  };
  renumber(part.tets);
  renumber(part.pyramids);
  renumber(part.hexes);

  // The fields' values at the given cells or nodes of the whole mesh.
  auto values_at = [](const FieldArrays& fields, const std::vector<std::size_t>& at) {
    FieldArrays part_fields;
    for (const auto& [name, field] : fields) {
      const auto m = static_cast<std::size_t>(field.components);
      auto& f = part_fields[name];
      f.components = field.components;
      f.values.reserve(m * at.size());
      for (std::size_t n : at)
        for (std::size_t k = 0; k < m; ++k) f.values.push_back(field.values[m * n + k]);
    }
    return part_fields;
  };
  const CellFields part_cells = values_at(cell_fields, cells);
  const PointFields part_points = values_at(point_fields, global);
  write_vtu(part, pvtu_piece_path(path, piece), part_cells, part_points);
  if (piece != 0) return;

  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n <PUnstructuredGrid "
      "GhostLevel=\"0\">\n  <PPoints>\n   <PDataArray type=\"Float64\" "
      "NumberOfComponents=\"3\"/>\n  </PPoints>\n";
  for (const auto& [fields, tag] :
       {std::pair{&cell_fields, "PCellData"}, std::pair{&point_fields, "PPointData"}}) {
    if (fields->empty()) continue;
    xml += fmt::format("  <{}>\n", tag);
    for (const auto& [name, field] : *fields)
      xml +=
          fmt::format("   <PDataArray type=\"Float32\" Name=\"{}\" NumberOfComponents=\"{}\"/>\n",
                      name, field.components);
    xml += fmt::format("  </{}>\n", tag);
  }
  for (int k = 0; k < pieces; ++k)
    xml += fmt::format("  <Piece Source=\"{}\"/>\n", pvtu_piece_path(path, k).filename().string());
  xml += " </PUnstructuredGrid>\n</VTKFile>\n";
  write_text_file(path, xml);
}

namespace {
// The boundary faces over the boundary's own nodes, not all the mesh's.
vtkSmartPointer<vtkPolyData> boundary_polydata(const HybridMesh& whole, bool triangulate) {
  const HybridMesh mesh = boundary_surface(whole);
  auto coords = vtkSmartPointer<vtkDoubleArray>::New();
  coords->SetNumberOfComponents(3);
  coords->SetNumberOfTuples(static_cast<vtkIdType>(mesh.nodes.size()));
  double* xyz = coords->GetPointer(0);
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
    for (int a = 0; a < 3; ++a) xyz[3 * n + a] = mesh.nodes[n][a];
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(coords);

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
  poly->SetPoints(points);
  poly->SetPolys(make_cell_array(offsets, connectivity));
  poly->GetCellData()->AddArray(patch);
  return poly;
}

}  // namespace

void write_boundary_vtp(const HybridMesh& mesh, const std::filesystem::path& path,
                        const PointFields& face_fields) {
  auto poly = boundary_polydata(mesh, false);
  const std::size_t faces = mesh.boundary_tris.size() + mesh.boundary_quads.size();
  for (const auto& [name, field] : face_fields) {
    if (field.values.size() != static_cast<std::size_t>(field.components) * faces)
      fail("internal: face field '{}' has {} values for {} faces", name, field.values.size(),
           faces);
    auto array = vtkSmartPointer<vtkDoubleArray>::New();
    array->SetName(name.c_str());
    array->SetNumberOfComponents(field.components);
    array->SetNumberOfTuples(static_cast<vtkIdType>(faces));
    std::copy(field.values.begin(), field.values.end(), array->GetPointer(0));
    poly->GetCellData()->AddArray(array);
  }
  auto writer = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
  writer->SetInputData(poly);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToNone();
  run_writer(writer.Get(), path);
}

void write_vtp(vtkPolyData* data, const std::filesystem::path& path) {
  auto writer = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
  writer->SetInputData(data);
  writer->SetDataModeToAppended();
  writer->SetCompressorTypeToZLib();
  run_writer(writer.Get(), path);
}

void write_stl(const HybridMesh& mesh, const std::filesystem::path& path) {
  auto writer = vtkSmartPointer<vtkSTLWriter>::New();
  writer->SetInputData(boundary_polydata(mesh, true));
  writer->SetFileTypeToBinary();
  run_writer(writer.Get(), path);
}

}  // namespace naris
