// Benchmark of `naris mesh` on the dissertation's mortar (3.4): a solid cylinder with a
// hemisphere removed from its top, as a 0/1 label volume (simulated segmented CT) at the six
// sizes of the dissertation and 512×512×256. For each: cells per type, nodes, meshing time,
// cells per second, peak memory, quality percentiles, and the time of VTK's
// vtkDiscreteFlyingEdges3D surface extraction on the same volume in the same run. File writing
// is timed separately.
//
// With --write-fields DIR it writes the inputs of scripts/bench mesh's end-to-end table instead:
// the mortar 256×256×128 and a sphere 64³ (radius 0.4·64) as signed distances (voxels, float).
//
// Usage: bench_mesh [--max N] [--no-write] [--out DIR] | bench_mesh --write-fields DIR
#include <fmt/format.h>
#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/log.h"
#include "mesh/image/write_volume.h"
#include "mesh/io/mesh_h5.h"
#include "mesh/io/write_vtk.h"
#include "mesh/mve/mve.h"
#include "mesh/quality/check.h"
#include "mesh/quality/quality.h"
#include "tests/bench/mortar.h"

namespace {

using namespace naris;

void reset_peak_memory() {
  std::ofstream("/proc/self/clear_refs") << "5";
}

Volume<float> sample(const mve::FieldSource& source) {
  Volume<float> v;
  v.frame = source.frame();
  v.values.resize(v.frame.voxel_count());
  const std::size_t plane = static_cast<std::size_t>(v.frame.dims[0]) * v.frame.dims[1];
  for (int k = 0; k < v.frame.dims[2]; ++k)
    source.read_slice(k, std::span<float>(v.values.data() + plane * k, plane));
  return v;
}

void write_fields(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  write_field_nrrd(sample(bench::MortarField(256, 256, 128)), dir / "mortar-sdf-256.nrrd");
  const int n = 64;
  Volume<float> sphere;
  sphere.frame.dims = {n, n, n};
  sphere.values.resize(sphere.frame.voxel_count());
  const double c = 0.5 * (n - 1), radius = 0.4 * n;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        sphere.values[sphere.frame.index(i, j, k)] = static_cast<float>(
            radius - std::sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c)));
  write_field_nrrd(sphere, dir / "sphere-sdf-64.nrrd");
}

}  // namespace

int main(int argc, char** argv) {
  int max_n = 512;
  bool write = true;
  std::filesystem::path out = std::filesystem::temp_directory_path() / "naris-bench-mesh";
  for (int a = 1; a < argc; ++a) {
    if (!std::strcmp(argv[a], "--max") && a + 1 < argc)
      max_n = std::atoi(argv[++a]);
    else if (!std::strcmp(argv[a], "--no-write"))
      write = false;
    else if (!std::strcmp(argv[a], "--out") && a + 1 < argc)
      out = argv[++a];
    else if (!std::strcmp(argv[a], "--write-fields") && a + 1 < argc) {
      write_fields(argv[++a]);
      return 0;
    }
  }
  set_verbosity(Verbosity::quiet);
  // Both meshers on one core: VTK's filters would otherwise use every core through its SMP
  // layer. (vtkSMPTools.h itself does not compile as C++20 with GCC 12, so the environment
  // variable VTK reads at start-up chooses the sequential backend.)
  setenv("VTK_SMP_BACKEND_IN_USE", "Sequential", 1);
  setenv("VTK_SMP_MAX_THREADS", "1", 1);
  std::filesystem::create_directories(out);

  // Build the case table before timing: it is made once per process.
  {
    Stopwatch table;
    bench::MortarField warm(4, 4, 4);
    mve::march_volume_elements(warm, mve::MveOptions{});
    std::printf("case table generated in %.3f s (once per process)\n\n", table.seconds());
  }

  std::printf("%-12s %9s %9s %8s %9s %9s %8s %9s %8s %8s %6s %8s %8s %8s %8s\n", "mortar", "hex",
              "pyramid", "tet", "nodes", "MVE s", "Mcell/s", "peak MB", "FE s", "MVE/FE", "valid",
              "ER p99", "skew p99", "SJ min", "write s");
  const int sizes[][3] = {{16, 16, 8},    {32, 32, 16},    {64, 64, 32},   {128, 128, 64},
                          {192, 192, 96}, {256, 256, 128}, {512, 512, 256}};
  for (const auto& s : sizes) {
    if (s[0] > max_n) break;
    // The same 0/1 volume for both meshers.
    Volume<float> labels = sample(bench::MortarField(s[0], s[1], s[2]));
    for (float& v : labels.values) v = v > 0.0f ? 1.0f : 0.0f;
    const mve::VolumeField field(labels, InsideRule::label, 1.0);

    reset_peak_memory();
    Stopwatch clock;
    HybridMesh mesh = mve::march_volume_elements(field, mve::MveOptions{});
    const double mve_seconds = clock.seconds();
    const double peak_mb = static_cast<double>(peak_memory_bytes()) / 1e6;

    // VTK's discrete flying edges on the same labels (surface only).
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(s[0], s[1], s[2]);
    auto scalars = vtkSmartPointer<vtkUnsignedCharArray>::New();
    scalars->SetNumberOfTuples(static_cast<vtkIdType>(labels.values.size()));
    for (std::size_t n = 0; n < labels.values.size(); ++n)
      scalars->SetValue(static_cast<vtkIdType>(n), static_cast<unsigned char>(labels.values[n]));
    image->GetPointData()->SetScalars(scalars);
    auto fe = vtkSmartPointer<vtkDiscreteFlyingEdges3D>::New();
    fe->SetInputData(image);
    fe->SetValue(0, 1.0);
    fe->ComputeNormalsOff();
    fe->ComputeGradientsOff();
    fe->ComputeScalarsOff();
    clock = Stopwatch();
    fe->Update();
    const double fe_seconds = clock.seconds();
    if (fe->GetOutput()->GetNumberOfPolys() == 0) std::printf("flying edges produced nothing!\n");

    const bool small = mesh.cell_count() < 3'000'000;
    const std::string valid = small ? (check_mesh(mesh).valid() ? "yes" : "NO") : "-";
    const auto q = summarize_quality(mesh, cell_quality(mesh));
    double write_seconds = 0.0;
    if (write) {
      clock = Stopwatch();
      write_mesh_h5(mesh, out / "mesh.h5");
      write_vtu(mesh, out / "mesh.vtu");
      write_seconds = clock.seconds();
    }
    std::printf(
        "%4dx%3dx%3d %9zu %9zu %8zu %9zu %9.3f %8.2f %9.0f %8.3f %8.2f %6s %8.2f %8.2f "
        "%8.3f %8.2f\n",
        s[0], s[1], s[2], mesh.hexes.size(), mesh.pyramids.size(), mesh.tets.size(),
        mesh.nodes.size(), mve_seconds, static_cast<double>(mesh.cell_count()) / mve_seconds / 1e6,
        peak_mb, fe_seconds, mve_seconds / fe_seconds, valid.c_str(), q.summary[3][0].p99,
        q.summary[3][1].p99, q.summary[3][3].min, write_seconds);
    std::fflush(stdout);
  }
  std::printf(
      "\nMVE s: meshing from the in-memory volume on one core (keep-largest included); "
      "FE s: vtkDiscreteFlyingEdges3D\n(surface only) on the same volume; peak MB: "
      "resident peak during meshing, input included; ER/skew/SJ: edge ratio,\n"
      "equi-angle skew, scaled Jacobian over all cells; write s: mesh.h5 + mesh.vtu.\n");

  // The same mortar as a signed distance (isopoints interpolated) against the 0/1 volume, side
  // by side in this run.
  std::printf("\n%-12s %14s %14s %12s %12s %12s %12s\n", "mortar", "cells (0/1)", "cells (SDF)",
              "MVE s (0/1)", "MVE s (SDF)", "Mcell/s 0/1", "Mcell/s SDF");
  for (const auto& s : sizes) {
    if (s[0] > max_n || s[0] < 128) continue;
    const Volume<float> sdf = sample(bench::MortarField(s[0], s[1], s[2]));
    Volume<float> labels = sdf;
    for (float& v : labels.values) v = v > 0.0f ? 1.0f : 0.0f;
    auto time_mve = [](const mve::FieldSource& field) {
      Stopwatch clock;
      const HybridMesh mesh = mve::march_volume_elements(field, mve::MveOptions{});
      return std::pair{mesh.cell_count(), clock.seconds()};
    };
    const auto [binary_cells, binary_seconds] =
        time_mve(mve::VolumeField(labels, InsideRule::label, 1.0));
    const auto [sdf_cells, sdf_seconds] = time_mve(mve::VolumeField(sdf, InsideRule::above, 0.0));
    std::printf("%4dx%3dx%3d %14zu %14zu %12.3f %12.3f %12.2f %12.2f\n", s[0], s[1], s[2],
                binary_cells, sdf_cells, binary_seconds, sdf_seconds,
                static_cast<double>(binary_cells) / binary_seconds / 1e6,
                static_cast<double>(sdf_cells) / sdf_seconds / 1e6);
    std::fflush(stdout);
  }
  return 0;
}
