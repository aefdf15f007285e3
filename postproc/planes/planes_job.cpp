#include "postproc/planes/planes_job.h"

#include <fmt/format.h>
#include <vtkAppendPolyData.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/json.h"
#include "core/log.h"
#include "core/units.h"
#include "mesh/io/write_vtk.h"
#include "postproc/figures/section_figure.h"
#include "postproc/planes/drawing.h"
#include "solver/airflow/solution_file.h"

namespace naris::planes {
namespace {

namespace fs = std::filesystem;
using Vec3 = Eigen::Vector3d;

std::string number(double x) {
  return fmt::format("{:.8g}", x);
}

Json measures_json(const Measures& m, double u_in, double inlet_flux,
                   const std::vector<std::string>& regions) {
  Json j;
  j["area_mm2"] = significant(m.area);
  j["perimeter_mm"] = significant(m.perimeter);
  j["raw_perimeter_mm"] = significant(m.raw_perimeter);
  j["hydraulic_diameter_mm"] = significant(m.hydraulic_diameter);
  j["raw_hydraulic_diameter_mm"] = significant(m.raw_hydraulic_diameter);
  j["flux_ml_s"] = significant(m.flux * kMlPerM3);
  if (inlet_flux > 0.0) {
    j["flux_to_inlet"] = significant(m.flux / inlet_flux);
    j["resolved_flux_to_inlet"] = significant(m.resolved_flux / inlet_flux);
  }
  j["mean_axial_m_s"] = significant(m.mean_axial);
  j["max_axial_m_s"] = significant(m.max_axial);
  j["max_speed_m_s"] = significant(m.max_speed);
  j["max_axial_u_in"] = significant(m.max_axial / u_in);
  j["max_speed_u_in"] = significant(m.max_speed / u_in);
  j["centroid_mm"] = {significant(m.centroid[0]), significant(m.centroid[1]),
                      significant(m.centroid[2])};
  for (std::size_t i = 0; i < regions.size() && i < m.region_flux.size(); ++i)
    j["flux_share"][regions[i]] = significant(m.flux != 0.0 ? m.region_flux[i] / m.flux : 0.0);
  return j;
}

}  // namespace

PlanesResult run_planes_job(const PlanesJob& job) {
  const Stopwatch clock;
  if (!(job.smoothing > 0.0)) fail("smoothing must be positive (voxels)");
  if (job.levels < 2 || job.levels > 64) fail("levels must lie in 2 … 64");
  if (job.arrows_across < 2 || job.arrows_across > 200) fail("arrows must lie in 2 … 200");
  if (job.distances_mm.empty() && job.planes.empty())
    fail("no planes: give distances (--at) or planes (--plane)");
  // Inputs, all checked before anything is written.
  const airflow::SolvedMesh solved = airflow::read_solved_mesh(job.solution, job.mesh);
  const HybridMesh& mesh = solved.mesh;
  const SectionAxis axis = job.distances_mm.empty() ? SectionAxis{} : section_axis(mesh, job.axis);
  const std::vector<SectionPlane> planes = section_planes(mesh, axis, job.distances_mm, job.planes);
  std::vector<std::string> groups;
  const std::vector<Crossing> crossings =
      job.crossings.empty() ? std::vector<Crossing>{} : read_crossings(job.crossings, groups);
  ensure_writable_folder(job.output);

  PlanesResult r;
  r.u_in = solved.state.u_in;
  r.reynolds = solved.state.reynolds;
  r.d_in_solution = solved.state.d_in_mm;
  r.voxel = voxel_size(mesh);
  r.smoothing_mm = job.smoothing * r.voxel;
  const std::vector<RegionBox> regions = region_boxes(mesh);
  for (const RegionBox& b : regions)
    r.regions.push_back(mesh.patch_names[static_cast<std::size_t>(b.patch)]);
  const SectionCutter cutter(mesh, solved.velocity, subgrid_velocity(solved), r.smoothing_mm);
  Progress progress("naris planes", planes.size());
  for (const SectionPlane& p : planes) {
    r.sections.push_back(cutter.cut(p, regions));
    progress.update(r.sections.size());
  }
  progress.finish();
  const int inlet = mesh.patch_id("inlet");
  if (inlet >= 0) r.inlet = cutter.patch(inlet);
  const double inlet_flux = r.inlet.flux;

  // planes.csv: a row for each plane (piece "all") and each of its pieces.
  std::vector<std::string> columns = {"plane",
                                      "label",
                                      "distance_mm",
                                      "piece",
                                      "area_mm2",
                                      "perimeter_mm",
                                      "raw_perimeter_mm",
                                      "hydraulic_diameter_mm",
                                      "flux_ml_s",
                                      "flux_to_inlet",
                                      "resolved_flux_to_inlet",
                                      "mean_axial_m_s",
                                      "max_axial_m_s",
                                      "max_speed_m_s",
                                      "max_axial_u_in",
                                      "max_speed_u_in"};
  for (const std::string& name : r.regions) columns.push_back("flux_share_" + name);
  CsvTable table(columns);
  auto row = [&](std::size_t k, const std::string& piece, const Measures& m) {
    const Section& s = r.sections[k];
    std::vector<std::string> f = {std::to_string(k + 1),
                                  s.plane.by_distance ? s.plane.label : "p/n",
                                  s.plane.by_distance ? number(s.plane.distance) : "",
                                  piece,
                                  number(m.area),
                                  number(m.perimeter),
                                  number(m.raw_perimeter),
                                  number(m.hydraulic_diameter),
                                  number(m.flux * kMlPerM3),
                                  inlet_flux > 0.0 ? number(m.flux / inlet_flux) : "",
                                  inlet_flux > 0.0 ? number(m.resolved_flux / inlet_flux) : "",
                                  number(m.mean_axial),
                                  number(m.max_axial),
                                  number(m.max_speed),
                                  number(m.max_axial / r.u_in),
                                  number(m.max_speed / r.u_in)};
    for (std::size_t i = 0; i < r.regions.size(); ++i)
      f.push_back(number(m.flux != 0.0 ? m.region_flux[i] / m.flux : 0.0));
    table.add_row(std::move(f));
  };
  for (std::size_t k = 0; k < r.sections.size(); ++k) {
    row(k, "all", r.sections[k].whole);
    for (std::size_t p = 0; p < r.sections[k].pieces.size(); ++p)
      row(k, std::to_string(p + 1), r.sections[k].pieces[p]);
  }

  // planes.vtp: every section, with its plane number.
  vtkNew<vtkAppendPolyData> append;
  for (std::size_t k = 0; k < r.sections.size(); ++k) {
    vtkPolyData* s = r.sections[k].surface;
    vtkNew<vtkIntArray> plane;
    plane->SetName("plane");
    plane->SetNumberOfTuples(s->GetNumberOfCells());
    plane->Fill(static_cast<int>(k + 1));
    s->GetCellData()->AddArray(plane);
    append->AddInputData(s);
  }
  append->Update();

  std::vector<figures::SectionFigure> drawn;
  if (job.figures)
    for (const Section& s : r.sections)
      drawn.push_back(
          section_figure(s, {job.levels, job.arrows_across, r.u_in, 0.0}, crossings, groups));

  table.write(job.output / "planes.csv");
  write_vtp(append->GetOutput(), job.output / "planes.vtp");
  for (std::size_t k = 0; k < drawn.size(); ++k) {
    const std::string stem = fmt::format("plane-{}", k + 1);
    figures::write_section_figure(drawn[k], job.output / (stem + ".png"),
                                  job.output / (stem + ".svg"));
    r.figure_files.push_back(stem + ".png");
    r.figure_files.push_back(stem + ".svg");
  }

  Json summary;
  summary["solution"] = fs::absolute(job.solution).string();
  summary["mesh"] = fs::absolute(solved.mesh_file).string();
  summary["reynolds"] = significant(r.reynolds);
  summary["inlet_speed_m_s"] = significant(r.u_in);
  summary["axis"] = job.distances_mm.empty() ? "" : job.axis;
  if (job.distances_mm.empty())
    summary["axis_direction"] = nullptr;  // planes by point and normal only: no axis
  else
    summary["axis_direction"] = {significant(axis.direction[0]), significant(axis.direction[1]),
                                 significant(axis.direction[2])};
  summary["voxel_mm"] = significant(r.voxel);
  summary["perimeter_smoothing_mm"] = significant(r.smoothing_mm);
  if (inlet >= 0) {
    Json in = measures_json(r.inlet, r.u_in, 0.0, {});
    in["d_in_solution_mm"] = significant(r.d_in_solution);
    // Which perimeter the solution's d_in (and so its Re) was computed with.
    const bool smoothed = std::abs(r.d_in_solution - r.inlet.hydraulic_diameter) <
                          std::abs(r.d_in_solution - r.inlet.raw_hydraulic_diameter);
    in["reynolds_defined_on"] = smoothed ? "smoothed perimeter" : "raw perimeter";
    summary["inlet"] = in;
  }
  Json list = Json::array();
  for (const Section& s : r.sections) {
    Json p;
    p["label"] = s.plane.label;
    if (s.plane.by_distance) p["distance_mm"] = significant(s.plane.distance);
    p["point_mm"] = {significant(s.plane.point[0]), significant(s.plane.point[1]),
                     significant(s.plane.point[2])};
    p["normal"] = {significant(s.plane.normal[0]), significant(s.plane.normal[1]),
                   significant(s.plane.normal[2])};
    p["pieces"] = s.pieces.size();
    if (!drawn.empty())
      p["crossings_drawn"] =
          drawn[static_cast<std::size_t>(&s - r.sections.data())].crossings.size();
    p["all"] = measures_json(s.whole, r.u_in, inlet_flux, r.regions);
    Json pieces = Json::array();
    for (const Measures& m : s.pieces)
      pieces.push_back(measures_json(m, r.u_in, inlet_flux, r.regions));
    p["per_piece"] = pieces;
    list.push_back(p);
  }
  summary["planes"] = list;
  summary["figures"] = r.figure_files;
  r.seconds = clock.seconds();
  summary["seconds"] = significant(r.seconds, 3);
  write_json_file(job.output / "summary.json", summary);
  return r;
}

std::string format_planes_summary(const PlanesJob& job, const PlanesResult& r) {
  std::string s = fmt::format("naris planes: {} plane(s) in {:.1f} s → {}", r.sections.size(),
                              r.seconds, job.output.string());
  if (r.inlet.area > 0.0)
    s += fmt::format(
        "\n  inlet: {:.4g} mm², flux {:.4g} mL/s, d_in {:.4g} mm (smoothed), {:.4g} mm (raw)",
        r.inlet.area, r.inlet.flux * kMlPerM3, r.inlet.hydraulic_diameter,
        r.inlet.raw_hydraulic_diameter);
  for (const Section& sec : r.sections) {
    const Measures& m = sec.whole;
    s += fmt::format(
        "\n  {:>10}: {} piece(s), {:.4g} mm², perimeter {:.4g} mm, flux {:.4g} of the inlet's "
        "(nodal velocity alone {:.4g}), max speed {:.3g} m/s",
        sec.plane.label, sec.pieces.size(), m.area, m.perimeter,
        r.inlet.flux > 0.0 ? m.flux / r.inlet.flux : 0.0,
        r.inlet.flux > 0.0 ? m.resolved_flux / r.inlet.flux : 0.0, m.max_speed);
  }
  return s;
}

}  // namespace naris::planes
