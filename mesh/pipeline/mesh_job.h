#pragma once
// `naris mesh` as a library call: image → field → cuts → MVE → patches → quality improvement →
// files. Every input problem is detected before the long work starts.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "mesh/image/read_volume.h"
#include "mesh/mve/mve.h"
#include "mesh/patches/patches.h"
#include "mesh/quality/check.h"
#include "mesh/quality/improve.h"
#include "mesh/quality/quality.h"
#include "mesh/quality/relocate.h"

namespace naris {

struct MeshJob {
  std::filesystem::path input;
  std::optional<double> threshold;  // inside is below it by default (air in CT)
  // Inside is one of these labels: "3", "3,5" (a union), or segment names ("right cavity").
  std::optional<std::string> label;
  InsideRule inside = InsideRule::below;  // with a threshold: its side (below or above)
  // A labelmap's wall on a smooth surface instead of the staircase (smooth_label.h), with
  // this Gaussian width in voxels (0: off).
  double smooth = 0.0;
  std::optional<std::string> inlet, outlet;
  std::vector<std::string> regions;  // name:box=... or name:sphere=...
  double outlet_extension = 0.0;     // mm of straight tube beyond the outlet (outlet_extension.h)
  bool keep_largest = true;
  bool improve = true;
  ImproveOptions improve_options;
  // Node relocation and wall-sliver removal after the collapses (relocate.h).
  bool relocate = true;
  RelocateOptions relocate_options;
  // Uniform refinements after the improvement (refine/subdivide.h): each multiplies the cells
  // by 8 and keeps the geometry, for mesh-convergence studies on one anatomy.
  int subdivisions = 0;
  bool check = true;  // verify conformity and watertightness
  int threads = 0;    // for quality and check (0: every core)
  std::filesystem::path output = "mesh.h5";
  bool write_vtu = true, write_stl = true, write_msh = true;
};

struct MeshJobResult {
  HybridMesh mesh;
  VolumeInfo input;
  double level = 0.0;                   // the threshold or label used
  std::vector<int> labels;              // a union of labels, meshed as one mask
  InsideRule rule = InsideRule::label;  // what inside meant
  mve::MveStats mve;
  struct Extension {
    int axis = -1;  // −1: none
    int voxels = 0;
    double length_mm = 0.0;
  } extension;
  ImproveStats improvement;
  RelocateStats relocation;
  std::size_t cells_before_subdivision = 0;  // with subdivisions
  QualityReport before, after;
  std::vector<CellQuality> quality;  // per cell of the final mesh, in its cell order
  std::vector<PatchReport> patches;
  double volume = 0.0;  // mm³, of the final mesh
  std::optional<MeshCheck> check;
  std::vector<std::pair<std::string, double>> seconds;  // stage → wall time
  std::vector<std::string> written;
};

MeshJobResult run_mesh_job(const MeshJob& job);
// Writes mesh.h5 (+ .xdmf), mesh.vtu, boundary.vtp, surface.stl, mesh.msh and mesh.json.
void write_mesh_outputs(const MeshJob& job, MeshJobResult& result);
std::string format_mesh_summary(const MeshJob& job, const MeshJobResult& result);

}  // namespace naris
