// Output files: the HDF5 round trip, the XDMF sidecar, VTU/VTP/STL read back by VTK, and the
// Gmsh file's sections and physical groups.
#include <gtest/gtest.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "mesh/io/mesh_h5.h"
#include "mesh/io/write_gmsh.h"
#include "mesh/io/write_vtk.h"
#include "tests/mesh/field_helpers.h"

namespace naris {
namespace {

namespace fs = std::filesystem;

HybridMesh sample_mesh() {
  testing::ArrayField f(9, 8, 7);
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 9; ++i)
        f.at(i, j, k) = static_cast<float>(
            3.2 - (Eigen::Vector3d(i, j, k) - Eigen::Vector3d(4.1, 3.7, 3.3)).norm());
  return mve::march_volume_elements(f, testing::quiet_options());
}

// This process's scratch folder, removed when the process ends (ctest runs every test in a
// process of its own; a folder per pid kept would pile up in /tmp).
fs::path temp_dir() {
  struct Scratch {
    fs::path path = fs::temp_directory_path() / ("naris-io-" + std::to_string(::getpid()));
    Scratch() { fs::create_directories(path); }
    ~Scratch() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  };
  static const Scratch scratch;
  return scratch.path;
}

// A cell field holding each cell's index, to see where a cell went, and a vector one,
// (i, 2i, −i) at cell i.
CellFields cell_index_field(const HybridMesh& m) {
  CellFields fields;
  auto& index = fields["index"].values;
  FieldArray& vector = fields["index_vector"];
  vector.components = 3;
  for (std::size_t c = 0; c < m.cell_count(); ++c) {
    const auto i = static_cast<double>(c);
    index.push_back(i);
    vector.values.insert(vector.values.end(), {i, 2 * i, -i});
  }
  return fields;
}

// The vector cell field agrees with the index field at every cell read back.
void expect_index_vector(vtkUnstructuredGrid* grid) {
  vtkDataArray* index = grid->GetCellData()->GetArray("index");
  vtkDataArray* vector = grid->GetCellData()->GetArray("index_vector");
  ASSERT_NE(vector, nullptr);
  ASSERT_EQ(vector->GetNumberOfComponents(), 3);
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c) {
    const double i = index->GetTuple1(c);
    const double* v = vector->GetTuple3(c);
    ASSERT_EQ(Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Vector3d(i, 2 * i, -i)) << c;
  }
}

// A .vtu or .pvtu read back by VTK's own reader of that format.
template <class Reader>
vtkSmartPointer<vtkUnstructuredGrid> read_grid(const fs::path& path) {
  auto reader = vtkSmartPointer<Reader>::New();
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader->GetOutput();
}

TEST(MeshH5, RoundTripIsExact) {
  const HybridMesh m = sample_mesh();
  ASSERT_FALSE(m.tets.empty());
  ASSERT_FALSE(m.hexes.empty());
  const fs::path p = temp_dir() / "mesh.h5";
  write_mesh_h5(m, p);
  EXPECT_TRUE(fs::exists(fs::path(p).replace_extension(".xdmf")));
  const HybridMesh r = read_mesh_h5(p);
  EXPECT_EQ(r.nodes, m.nodes);
  EXPECT_EQ(r.tets, m.tets);
  EXPECT_EQ(r.pyramids, m.pyramids);
  EXPECT_EQ(r.hexes, m.hexes);
  EXPECT_EQ(r.boundary_tris, m.boundary_tris);
  EXPECT_EQ(r.boundary_tri_patch, m.boundary_tri_patch);
  EXPECT_EQ(r.boundary_quads, m.boundary_quads);
  EXPECT_EQ(r.patch_names, m.patch_names);
  for (const auto& e : fs::directory_iterator(p.parent_path()))
    EXPECT_EQ(e.path().string().find(".part-"), std::string::npos) << "leftover " << e.path();
}

TEST(MeshH5, RejectsFilesThatAreNotMeshes) {
  const fs::path p = temp_dir() / "not-a-mesh.h5";
  std::ofstream(p) << "hello";
  EXPECT_THROW(read_mesh_h5(p), Error);
  EXPECT_THROW(read_mesh_h5(temp_dir() / "absent.h5"), Error);
}

TEST(Vtk, VtuAndStlReadBack) {
  const HybridMesh m = sample_mesh();
  const fs::path dir = temp_dir();
  write_vtu(m, dir / "mesh.vtu", cell_index_field(m));
  const auto grid = read_grid<vtkXMLUnstructuredGridReader>(dir / "mesh.vtu");
  ASSERT_EQ(grid->GetNumberOfCells(), static_cast<vtkIdType>(m.cell_count()));
  ASSERT_EQ(grid->GetNumberOfPoints(), static_cast<vtkIdType>(m.nodes.size()));
  const vtkIdType first_hex = static_cast<vtkIdType>(m.tets.size() + m.pyramids.size());
  EXPECT_EQ(grid->GetCellType(0), VTK_TETRA);
  EXPECT_EQ(grid->GetCellType(first_hex), VTK_HEXAHEDRON);
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  grid->GetCellPoints(first_hex, n, ids);
  ASSERT_EQ(n, 8);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(ids[k], m.hexes[0][k]);
  double p[3];
  grid->GetPoint(5, p);
  EXPECT_EQ(Eigen::Vector3d(p[0], p[1], p[2]), m.nodes[5]);
  vtkDataArray* read_index = grid->GetCellData()->GetArray("index");
  ASSERT_NE(read_index, nullptr);
  EXPECT_EQ(read_index->GetTuple1(first_hex), static_cast<double>(first_hex));
  expect_index_vector(grid);
  write_stl(m, dir / "surface.stl");
  auto stl = vtkSmartPointer<vtkSTLReader>::New();
  stl->SetFileName((dir / "surface.stl").c_str());
  stl->Update();
  EXPECT_EQ(stl->GetOutput()->GetNumberOfCells(),
            static_cast<vtkIdType>(m.boundary_tris.size() + 2 * m.boundary_quads.size()));
}

// Three pieces, each the cells of one third of the nodes (by smallest node, as the MPI ranks
// share them), read back through the .pvtu by VTK's parallel reader: every cell once, with its
// cell value, and every point's field equal to the field of its coordinates.
TEST(Vtk, PvtuPiecesCoverTheMeshOnce) {
  const HybridMesh m = sample_mesh();
  const fs::path dir = temp_dir() / "pvtu";
  fs::create_directories(dir);
  const CellFields cells = cell_index_field(m);
  PointFields points;
  auto& coordinates = points["x"];
  coordinates.components = 3;
  for (const auto& x : m.nodes)
    for (int k = 0; k < 3; ++k) coordinates.values.push_back(x[k]);
  constexpr int kPieces = 3;
  const auto n = static_cast<std::int64_t>(m.nodes.size());
  for (int piece = 0; piece < kPieces; ++piece)
    write_pvtu_piece(
        m, dir / "flow.pvtu", piece, kPieces,
        [&](std::span<const NodeId> cell) {
          return *std::min_element(cell.begin(), cell.end()) * kPieces / n == piece;
        },
        cells, points);
  for (int piece = 0; piece < kPieces; ++piece)
    EXPECT_TRUE(fs::exists(dir / ("flow_" + std::to_string(piece) + ".vtu"))) << piece;

  const auto grid = read_grid<vtkXMLPUnstructuredGridReader>(dir / "flow.pvtu");
  ASSERT_EQ(grid->GetNumberOfCells(), static_cast<vtkIdType>(m.cell_count()));
  // Nodes on a piece boundary appear in each piece that uses them.
  EXPECT_GT(grid->GetNumberOfPoints(), static_cast<vtkIdType>(m.nodes.size()));
  vtkDataArray* read_index = grid->GetCellData()->GetArray("index");
  ASSERT_NE(read_index, nullptr);
  std::vector<int> seen(m.cell_count(), 0);
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
    ++seen[static_cast<std::size_t>(read_index->GetTuple1(c))];
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(m.cell_count()));
  expect_index_vector(grid);
  vtkDataArray* read_x = grid->GetPointData()->GetArray("x");
  ASSERT_NE(read_x, nullptr);
  ASSERT_EQ(read_x->GetNumberOfComponents(), 3);
  double worst = 0.0;
  for (vtkIdType p = 0; p < grid->GetNumberOfPoints(); ++p) {
    double x[3];
    grid->GetPoint(p, x);
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(read_x->GetComponent(p, k) - x[k]));
  }
  EXPECT_LT(worst, 1e-5);  // the fields are Float32
}

TEST(Gmsh, HasPhysicalGroupsAndEveryElement) {
  HybridMesh m = sample_mesh();
  const fs::path p = temp_dir() / "mesh.msh";
  write_gmsh22(m, p);
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "$MeshFormat");
  std::getline(in, line);
  EXPECT_EQ(line, "2.2 0 8");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("\"wall\""), std::string::npos);
  EXPECT_NE(text.find("3 " + std::to_string(m.patch_names.size() + 1) + " \"fluid\""),
            std::string::npos);
  const auto at = text.find("$Elements\n");
  ASSERT_NE(at, std::string::npos);
  const std::size_t count = std::stoul(text.substr(at + 10));
  EXPECT_EQ(count, m.cell_count() + m.boundary_tris.size() + m.boundary_quads.size());
}

}  // namespace
}  // namespace naris
