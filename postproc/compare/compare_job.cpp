#include "postproc/compare/compare_job.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/log.h"
#include "mesh/io/mesh_h5.h"
#include "mesh/patches/section_planes.h"
#include "postproc/figures/canvas.h"
#include "postproc/figures/line_plot.h"
#include "postproc/figures/section_figure.h"
#include "postproc/planes/drawing.h"
#include "postproc/planes/sections.h"
#include "postproc/report/report.h"
#include "solver/airflow/solution_file.h"

namespace naris::compare {
namespace {

namespace fs = std::filesystem;
constexpr const char* kFates[] = {"outlet", "wall", "max-time", "stagnated"};

// A case folder (case.yaml) or a results folder, to its name and results.
Subject subject_of(const fs::path& input) {
  Subject s;
  const fs::path case_file = input / "case.yaml";
  if (fs::is_regular_file(case_file)) {
    YAML::Node root;
    try {
      root = YAML::LoadFile(case_file.string());
    } catch (const YAML::Exception& e) {
      fail("{}: not valid YAML: {}", case_file.string(), e.what());
    }
    s.name =
        root["name"] ? root["name"].as<std::string>() : fs::absolute(input).filename().string();
    const fs::path output = root["output"] ? root["output"].as<std::string>() : "results";
    s.results = output.is_absolute() ? output : input / output;
  } else if (fs::is_directory(input / "solution")) {
    s.results = input;
    fs::path named = fs::absolute(input).lexically_normal();
    if (named.filename().empty()) named = named.parent_path();
    s.name = named.filename() == "results" ? named.parent_path().filename().string()
                                           : named.filename().string();
  } else {
    fail("{}: neither a case folder (case.yaml) nor a results folder (solution/)", input.string());
  }
  const fs::path solution = s.results / "solution" / "summary.json";
  const fs::path planes = s.results / "planes" / "summary.json";
  if (!fs::is_regular_file(solution))
    fail("{}: no solve results ({} is missing; run the case's solve stage)", s.name,
         solution.string());
  if (!fs::is_regular_file(planes))
    fail("{}: no planes stage ({} is missing; add planes: to the case, or run naris planes)",
         s.name, planes.string());
  s.solution = read_json_file(solution);
  s.planes = read_json_file(planes);
  bool valid = s.planes.contains("planes") && s.planes["planes"].is_array() &&
               s.planes.contains("axis_direction");
  if (valid)
    for (const Json& p : s.planes["planes"])
      valid = valid && p.contains("label") && p.contains("point_mm") && p.contains("normal") &&
              p.contains("all") && p["all"].contains("area_mm2");
  if (!valid) fail("{}: not a summary of naris planes (rerun the planes stage)", planes.string());
  const fs::path trace = s.results / "trace" / "summary.json";
  if (fs::is_regular_file(trace)) s.trace = read_json_file(trace);
  s.solution_state = airflow::read_solution_h5(s.results / "solution" / "solution.h5");
  if (s.solution_state.mesh_file.empty()) fail("{}: its solution names no mesh file", s.name);
  s.units = read_mesh_units(s.solution_state.mesh_file);
  return s;
}

std::string number(const Json& j) {
  if (j.is_number()) return fmt::format("{:.6g}", j.get<double>());
  if (j.is_string()) return j.get<std::string>();
  return "";
}

const Json& at(const Json& j, const char* key, const Subject& s, const char* file) {
  if (!j.contains(key)) fail("{}: {} has no '{}'", s.name, file, key);
  return j[key];
}

Eigen::Vector3d vector_of(const Json& j) {
  return Eigen::Vector3d(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
}

// The table: one row per subject, numbers as in the summaries (six significant digits).
void build_table(CompareResult& r) {
  const Subject& first = r.subjects.front();
  // Column suffixes: a plane by distance by its label ("33.5 mm"), one by point and normal by
  // its number (its label holds commas).
  std::vector<std::string> labels;
  for (const Json& p : first.planes["planes"])
    labels.push_back(p.contains("distance_mm") ? p["label"].get<std::string>()
                                               : fmt::format("plane{}", labels.size() + 1));
  std::vector<std::string> regions;  // the flux shares the first subject's planes have
  if (!first.planes["planes"].empty() && first.planes["planes"][0]["all"].contains("flux_share"))
    for (const auto& [name, value] : first.planes["planes"][0]["all"]["flux_share"].items())
      regions.push_back(name);
  std::set<std::string> group_fates;
  std::vector<std::string> traced;
  for (const Subject& s : r.subjects)
    if (!s.trace.is_null())
      for (const Json& g : s.trace["per_group"])
        for (const char* fate : kFates) {
          const std::string key = fmt::format("{}_{}", g["group"].get<std::string>(), fate);
          if (group_fates.insert(key).second) traced.push_back(key);
        }
  r.columns = {"subject",          "inlet_area_mm2",     "d_in_mm",
               "d_in_smoothed_mm", "u_in_m_s",           "flow_ml_s",
               "pressure_drop_pa", "resistance_pa_s_ml", "max_speed_m_s"};
  for (const std::string& l : labels)
    for (const char* q : {"area_mm2", "perimeter_mm", "max_speed_m_s"})
      r.columns.push_back(fmt::format("{}_{}", q, l));
  for (const std::string& region : regions)
    for (const std::string& l : labels) r.columns.push_back(fmt::format("share_{}_{}", region, l));
  for (const std::string& k : traced) r.columns.push_back(k);
  for (const Subject& s : r.subjects) {
    const Json& sol = s.solution;
    std::vector<std::string> row = {
        s.name,
        number(at(sol, "inlet_area_mm2", s, "solution/summary.json")),
        number(at(sol, "inlet_hydraulic_diameter_mm", s, "solution/summary.json")),
        s.planes.contains("inlet") ? number(s.planes["inlet"]["hydraulic_diameter_mm"]) : "",
        number(at(sol, "inlet_speed_m_s", s, "solution/summary.json")),
        number(at(sol, "flow_ml_s", s, "solution/summary.json")),
        number(at(sol, "pressure_drop_pa", s, "solution/summary.json")),
        number(at(sol, "resistance_pa_s_ml", s, "solution/summary.json")),
        number(at(sol, "max_speed_m_s", s, "solution/summary.json"))};
    const Json& planes = s.planes["planes"];
    for (const Json& p : planes)
      for (const char* q : {"area_mm2", "perimeter_mm", "max_speed_m_s"})
        row.push_back(number(p["all"][q]));
    for (const std::string& region : regions)
      for (const Json& p : planes)
        row.push_back(p["all"].contains("flux_share") && p["all"]["flux_share"].contains(region)
                          ? number(p["all"]["flux_share"][region])
                          : "");
    std::map<std::string, std::string> fates;  // "<group>_<fate>" → count
    if (!s.trace.is_null())
      for (const Json& g : s.trace["per_group"])
        for (const char* fate : kFates)
          fates[fmt::format("{}_{}", g["group"].get<std::string>(), fate)] = number(g[fate]);
    for (const std::string& k : traced) row.push_back(fates[k]);
    r.rows.push_back(std::move(row));
  }
}

// The table transposed, one column per subject: it stays readable with many planes.
report::Table transposed(const CompareResult& r) {
  report::Table t{{"quantity"}, {}};
  for (const Subject& s : r.subjects) t.header.push_back(s.name);
  for (std::size_t c = 1; c < r.columns.size(); ++c) {
    std::vector<std::string> row{r.columns[c]};
    for (const auto& subject_row : r.rows) row.push_back(subject_row[c]);
    t.rows.push_back(std::move(row));
  }
  return t;
}

}  // namespace

CompareResult run_compare_job(const CompareJob& job) {
  const Stopwatch clock;
  if (job.inputs.size() < 2) fail("compare needs two subjects or more");
  if (!(job.profile_step > 0.0 && job.profile_step <= 10.0))
    fail("profile-step {} mm: give a spacing in (0, 10] mm", job.profile_step);
  CompareResult r;
  std::set<std::string> names;
  for (const fs::path& input : job.inputs) {
    r.subjects.push_back(subject_of(input));
    if (!names.insert(r.subjects.back().name).second)
      fail("two subjects are named '{}': give the cases different names", r.subjects.back().name);
  }
  // The same planes (labels and axis) for every subject.
  const Subject& first = r.subjects.front();
  auto labels_of = [](const Subject& s) {
    std::vector<std::string> l;
    for (const Json& p : s.planes["planes"]) l.push_back(p["label"].get<std::string>());
    return l;
  };
  const auto labels = labels_of(first);
  for (const Subject& s : r.subjects) {
    if (s.units != first.units)
      fail("{} is in {} and {} in {}: compare subjects meshed in the same units", first.name,
           first.units, s.name, s.units);
    if (labels_of(s) != labels)
      fail("{} and {} have different planes: give both the same planes (at, plane)", first.name,
           s.name);
    if (s.planes.value("axis", std::string()) != first.planes.value("axis", std::string()))
      fail("{} and {} place their planes along different axes", first.name, s.name);
  }
  if (job.plane < 1 || job.plane > static_cast<int>(labels.size()))
    fail("plane {}: the subjects have planes 1 … {}", job.plane, labels.size());
  ensure_writable_folder(job.output);
  build_table(r);
  CsvTable table(r.columns);
  for (const auto& row : r.rows) table.add_row(row);

  // The figures need each subject's solution and mesh.
  std::vector<figures::SectionFigure> panels;
  figures::LinePlot profile;
  profile.title = "Cross-sectional area along the airway";
  profile.x_label = "distance from the anterior tip (mm)";
  profile.y_label = "area (mm²)";
  if (job.figures) {
    std::vector<planes::Section> sections;
    std::vector<double> u_in;
    double top = 0.0;
    Progress progress("naris compare", r.subjects.size());
    for (std::size_t i = 0; i < r.subjects.size(); ++i) {
      Subject& s = r.subjects[i];
      const airflow::SolvedMesh solved =
          airflow::attach_mesh(std::move(s.solution_state), s.results / "solution" / "solution.h5");
      const double voxel = planes::voxel_size(solved.mesh);
      const planes::SectionCutter cutter(solved.mesh, solved.velocity,
                                         planes::subgrid_velocity(solved), voxel);
      const Json& p = s.planes["planes"][static_cast<std::size_t>(job.plane - 1)];
      SectionPlane plane{vector_of(p["point_mm"]), vector_of(p["normal"]),
                         p["label"].get<std::string>(), p.value("distance_mm", 0.0),
                         p.contains("distance_mm")};
      sections.push_back(cutter.cut(plane));
      u_in.push_back(solved.state.u_in);
      top = std::max(top, sections.back().whole.max_speed);
      progress.update(i + 1);
      // Area against distance along the subject's own axis (none for planes by point and
      // normal alone).
      if (!s.planes["axis_direction"].is_array()) continue;
      const Eigen::Vector3d axis = vector_of(s.planes["axis_direction"]);
      double tip = std::numeric_limits<double>::infinity(), end = -tip;
      for (const Eigen::Vector3d& x : solved.mesh.nodes)
        tip = std::min(tip, axis.dot(x)), end = std::max(end, axis.dot(x));
      figures::Series series;
      series.rgb = figures::group_colour(static_cast<int>(i));
      // The minimum area among the sections the whole flow crosses (90 % of the inlet's flux):
      // in front of an oblique naris a plane cuts the vestibule's mouth only.
      const double inlet_flux = s.planes["inlet"]["flux_ml_s"].get<double>() * 1e-6;
      std::optional<std::size_t> smallest;
      for (double d = 0.5 * job.profile_step; d < end - tip; d += job.profile_step) {
        const SectionPlane cut{(tip + d) * axis, axis, "", d, true};
        double area = NAN, flux = 0.0;
        try {
          const auto section = cutter.cut(cut);
          area = section.whole.area, flux = section.whole.flux;
        } catch (const Error&) {  // a plane in a gap of the airway along the axis
        }
        series.x.push_back(d);
        series.y.push_back(area);
        if (std::isfinite(area) && std::abs(flux) >= 0.9 * inlet_flux &&
            (!smallest || area < series.y[*smallest]))
          smallest = series.x.size() - 1;
      }
      if (series.x.size() < 2)
        fail("{}: the airway is too short for a profile step of {} mm", s.name, job.profile_step);
      if (!smallest)
        fail(
            "{}: no section along the axis carries the inlet's flux (a plane cuts the airway "
            "twice?): no minimum area",
            s.name);
      series.markers = {*smallest};
      series.label = fmt::format("{} (min {:.0f} mm² at {:.0f} mm)", s.name, series.y[*smallest],
                                 series.x[*smallest]);
      profile.series.push_back(std::move(series));
    }
    progress.finish();
    for (std::size_t i = 0; i < sections.size(); ++i) {
      figures::SectionFigure f = planes::section_figure(sections[i], {15, 25, u_in[i], top});
      f.title = fmt::format("{}: max {:.2f} m/s", r.subjects[i].name, sections[i].whole.max_speed);
      panels.push_back(std::move(f));
    }
  }

  const report::Table by_quantity = transposed(r);
  table.write(job.output / "compare.csv");
  r.files.push_back("compare.csv");
  write_text_file(job.output / "compare.md",
                  fmt::format("# Comparison of {} subjects\n\n{}", r.subjects.size(),
                              report::markdown_table(by_quantity)));
  r.files.push_back("compare.md");
  if (job.figures) {
    const Json& p = first.planes["planes"][static_cast<std::size_t>(job.plane - 1)];
    const std::string stem = fmt::format("plane-{}", job.plane);
    figures::write_section_grid(
        panels,
        fmt::format("Plane {} ({}) of every subject", job.plane, p["label"].get<std::string>()),
        "Speed: 15 bands and contours in equal steps from 0 at the wall to the largest maximum\n"
        "of all subjects (one colour scale). Arrows: the secondary (in-plane) velocity, one "
        "scale.\nSeen from the anterior; one millimetre scale.",
        job.output / (stem + ".png"), job.output / (stem + ".svg"));
    r.files.push_back(stem + ".png");
    r.files.push_back(stem + ".svg");
    if (!profile.series.empty()) {
      figures::write_png(profile, job.output / "area-distance.png");
      r.files.push_back("area-distance.png");
    }
  }
  report::Report rep;
  rep.title = fmt::format("naris comparison of {} subjects", r.subjects.size());
  rep.version = job.version;
  report::Section numbers{"Every subject's numbers", "From each subject's summary files.", {}, {}};
  numbers.tables.push_back(by_quantity);
  rep.sections.push_back(std::move(numbers));
  if (job.figures)
    rep.sections.push_back(
        {"Figures",
         "",
         {},
         {job.output / fmt::format("plane-{}.png", job.plane), job.output / "area-distance.png"}});
  for (const Subject& s : r.subjects)
    rep.settings += fmt::format("{}: {}\n", s.name, fs::absolute(s.results).string());
  report::write_report(rep, job.output);
  r.files.push_back("report.html");
  r.files.push_back("report.md");
  r.seconds = clock.seconds();
  return r;
}

std::string format_compare_summary(const CompareJob& job, const CompareResult& r) {
  std::string s = fmt::format("naris compare: {} subjects in {:.1f} s → {}", r.subjects.size(),
                              r.seconds, job.output.string());
  for (std::size_t i = 0; i < r.subjects.size(); ++i)
    s += fmt::format("\n  {:<24} flow {} mL/s, Δp {} Pa, max speed {} m/s", r.subjects[i].name,
                     r.rows[i][5], r.rows[i][6], r.rows[i][8]);
  return s;
}

}  // namespace naris::compare
