#pragma once
// `naris trace` as a library call: a solution (+ its mesh) to particle paths, their fates,
// deposits and crossings of cross-section planes (docs/method/particles.md; files in
// docs/formats.md). Under MPI every rank holds the whole mesh and tracks every size-th
// particle; rank 0 gathers and writes, so the results do not depend on the ranks.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "solver/particles/release.h"
#include "solver/particles/tracker.h"

namespace naris::particles {

struct TraceJob {
  std::filesystem::path solution;             // solution.h5 from naris solve
  std::optional<std::filesystem::path> mesh;  // default: the mesh solution.h5 names
  std::filesystem::path output = "trace";
  // Release: dissertation (three groups on the naris), grid, random (flux-weighted), line,
  // points (a CSV file).
  std::string release = "dissertation";
  int count = 10;          // per group; points across (grid); particles (random, line)
  double offset_mm = 1.0;  // from the naris wall (dissertation, grid)
  int seed = 1;            // random
  std::string line;        // "x0,y0,z0;x1,y1,z1" (mm)
  std::filesystem::path points;
  // Particles: one species per diameter (µm; 0 or none given: massless tracers), each of the
  // density given (one for all, or one per diameter).
  std::vector<double> diameters_um;
  std::vector<double> densities = {1000.0};
  // Planes: distances (mm) from the airway's most anterior point along `plane_axis` (the inlet →
  // outlet axis, or an image axis: section_planes.h), and planes by point and normal
  // ("p=x,y,z;n=nx,ny,nz", mm).
  std::vector<double> plane_distances_mm;
  std::string plane_axis = "inlet-outlet";
  std::vector<std::string> planes;
  std::string gravity = "down";  // down (−z, the patient's inferior in LPS), none, or gx,gy,gz m/s²
  std::string drag = "schiller-naumann";
  double tolerance = 1e-4;       // local error per step, in cell sizes
  double max_step = 0.5;         // cell sizes per step
  double max_time = 2.0;         // s
  double stagnation = 1e-4;      // in units of U_in
  double path_spacing_mm = 0.5;  // between recorded path points
  int max_paths = 20000;         // paths written for the first this many particles
};

struct TraceCounts {
  std::string group;
  double diameter_um = 0.0, density = 0.0;
  int released = 0;
  int fates[kFates] = {};
  std::vector<int> deposited;  // per patch (wall fates)
  std::vector<int> visited;    // per region patch: particles that passed through its box
};

struct TraceResult {
  int particles = 0, lost = 0, ranks = 1;
  std::vector<TraceCounts> counts;  // per group and species
  std::vector<std::string> patch_names;
  std::vector<int> region_patches;  // the patches whose boxes count visits
  long steps = 0, cell_tests = 0;
  double track_seconds = 0.0, seconds = 0.0;
  // For the figures (rank 0): every particle's result, its group, the planes, and the wall as
  // triangles (mm).
  std::vector<ParticleResult> tracks;
  std::vector<int> track_group;
  std::vector<std::string> groups;
  std::vector<Plane> planes;
  std::vector<std::string> plane_labels;
  std::vector<std::array<Vec3, 3>> wall;
};

// Throws naris::Error for a bad input (a solution of another mesh, a release point outside the
// airway, a group that cannot be placed, a bad species or plane) before it writes anything, and
// when a particle is lost.
TraceResult run_trace_job(const TraceJob& job);
std::string format_trace_summary(const TraceJob& job, const TraceResult& result);

}  // namespace naris::particles
