// The real neonatal airway (../shared/data/neonate-a.nrrd), cropped across its second axis as
// the data README describes, against the numbers measured independently there.
#include <gtest/gtest.h>

#include <filesystem>

#include "mesh/pipeline/mesh_job.h"

namespace naris {
namespace {

namespace fs = std::filesystem;

TEST(Neonate, MeshesIntoOneConformingWatertightComponentWithInletAndOutlet) {
  const fs::path data = fs::path(NARIS_SHARED_DATA) / "neonate-a.nrrd";
  if (!fs::exists(data)) GTEST_SKIP() << "shared data absent: " << data;
  MeshJob job;
  job.input = data;
  job.inlet = "j=19";
  job.outlet = "j=285";
  job.output = fs::temp_directory_path() / "naris-neonate-test" / "mesh.h5";
  const MeshJobResult r = run_mesh_job(job);
  ASSERT_TRUE(r.check.has_value());
  EXPECT_TRUE(r.check->valid()) << r.check->describe();
  EXPECT_GE(r.mve.components, 2u);  // the specks the README lists exist and are dropped
  EXPECT_EQ(r.mve.dropped_components + 1, r.mve.components);
  EXPECT_GT(r.mesh.hexes.size(), 0u);
  EXPECT_GT(r.mesh.pyramids.size(), 0u);
  EXPECT_GT(r.mesh.tets.size(), 0u);
  double inlet = 0, outlet = 0;
  for (const auto& p : r.patches) {
    if (p.name == "inlet") inlet = p.area;
    if (p.name == "outlet") outlet = p.area;
  }
  // README: inlet 22.5 mm² (OpenFOAM on a snappyHexMesh of the same crop); airway ≈ 4.1 mL.
  EXPECT_NEAR(inlet, 22.5, 0.05 * 22.5);
  EXPECT_GT(outlet, 0.0);
  EXPECT_NEAR(mesh_volume(r.mesh) / 1000.0, 4.1, 0.2);
  // The frame is rotated and mirrored (LPS): every node maps back inside the crop box.
  const Volume<float> image = read_volume(data);
  for (const auto& x : r.mesh.nodes) {
    const Eigen::Vector3d ijk = image.frame.continuous_index(x);
    ASSERT_GE(ijk[1], 19.0 - 1e-9);
    ASSERT_LE(ijk[1], 285.0 + 1e-9);
    ASSERT_GE(ijk[0], -1e-9);
    ASSERT_LE(ijk[0], 46.0 + 1e-9);
  }
  std::printf(
      "[ info ] neonate: %zu cells (%zu hex, %zu pyramid, %zu tet), %zu nodes, inlet "
      "%.2f mm², outlet %.2f mm², %zu components\n",
      r.mesh.cell_count(), r.mesh.hexes.size(), r.mesh.pyramids.size(), r.mesh.tets.size(),
      r.mesh.nodes.size(), inlet, outlet, r.mve.components);
}

}  // namespace
}  // namespace naris
