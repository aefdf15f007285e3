#pragma once
// `naris planes` as a library call: a solution (+ its mesh) to cross-sections on planes normal
// to the anterior–posterior axis (section 4.3.1, Table 4.3, Figs. 4.6–4.11): planes.csv,
// planes.vtp, summary.json and per plane a figure (PNG and SVG) (docs/formats.md;
// docs/method/planes.md).
#include <filesystem>
#include <string>
#include <vector>

#include "postproc/planes/sections.h"

namespace naris::planes {

struct PlanesJob {
  std::filesystem::path solution;  // solution.h5 from naris solve
  std::filesystem::path mesh;      // empty: the mesh solution.h5 names
  std::filesystem::path output = "planes";
  // Distances (mm) from the airway's most anterior point along `axis`, and planes by point and
  // normal ("p=x,y,z;n=nx,ny,nz", mm).
  std::vector<double> distances_mm = {33.5, 44.0, 54.5, 65.0, 75.5, 85.0};
  std::vector<std::string> planes;
  std::string axis = "inlet-outlet";  // or x, y, z, -x, -y, -z
  double smoothing = 1.0;             // the perimeter's Gaussian width, in voxels
  int levels = 15;                    // speed bands and contour levels
  int arrows_across = 25;             // secondary-velocity arrows across the larger extent
  bool figures = true;
  std::filesystem::path crossings;  // crossings.csv from naris trace (empty: none)
};

struct PlanesResult {
  std::vector<Section> sections;
  Measures inlet;  // the inlet patch measured as a section (perimeter smoothed alike)
  double u_in = 0.0, reynolds = 0.0, d_in_solution = 0.0;  // m/s, −, mm (the solution's d_in)
  double voxel = 0.0, smoothing_mm = 0.0;
  std::vector<std::string> regions;       // region patch names, as in Measures::region_flux
  std::vector<std::string> figure_files;  // relative to the output folder
  double seconds = 0.0;
};

// Throws naris::Error for a bad input (a solution of another mesh, a plane that misses the
// airway, a distance beyond its length, a bad option) before it writes anything.
PlanesResult run_planes_job(const PlanesJob& job);
std::string format_planes_summary(const PlanesJob& job, const PlanesResult& result);

}  // namespace naris::planes
