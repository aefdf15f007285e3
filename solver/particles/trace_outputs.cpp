#include "solver/particles/trace_outputs.h"

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataWriter.h>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/json.h"
#include "core/units.h"
#include "mesh/io/write_vtk.h"

namespace naris::particles {
namespace {

namespace fs = std::filesystem;

vtkSmartPointer<vtkIntArray> int_array(const char* name) {
  auto a = vtkSmartPointer<vtkIntArray>::New();
  a->SetName(name);
  return a;
}
vtkSmartPointer<vtkFloatArray> float_array(const char* name) {
  auto a = vtkSmartPointer<vtkFloatArray>::New();
  a->SetName(name);
  return a;
}

std::string number(double x) {
  return fmt::format("{:.10g}", x);
}

struct Particle {
  int id, point, kind, group;
};

}  // namespace

void write_trace_outputs(const TraceData& d) {
  const fs::path& out = d.job.output;
  fs::create_directories(out);
  const int per_kind = static_cast<int>(d.release.points.size());
  auto particle = [&](int id) {
    const int p = id % per_kind;
    return Particle{id, p, id / per_kind, d.release.group[static_cast<std::size_t>(p)]};
  };
  auto diameter_um = [&](int kind) {
    return d.kinds[static_cast<std::size_t>(kind)].diameter * 1e6;
  };
  auto patch_name = [&](int patch) {
    return patch >= 0 ? d.mesh.patch_names[static_cast<std::size_t>(patch)] : std::string();
  };

  // paths.vtp: a polyline per recorded particle (mm), time and speed per point.
  {
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToFloat();
    auto lines = vtkSmartPointer<vtkCellArray>::New();
    auto time = float_array("time_s"), speed = float_array("speed_m_s");
    auto id = int_array("particle"), group = int_array("group"), fate = int_array("fate");
    auto diameter = float_array("diameter_um");
    for (std::size_t i = 0; i < d.particles.size(); ++i) {
      const ParticleResult& r = d.particles[i];
      if (r.path.size() < 2) continue;
      const Particle p = particle(static_cast<int>(i));
      lines->InsertNextCell(static_cast<vtkIdType>(r.path.size()));
      for (const PathPoint& q : r.path) {
        const Vec3 x = q.x / kMm;
        lines->InsertCellPoint(points->InsertNextPoint(x[0], x[1], x[2]));
        time->InsertNextValue(static_cast<float>(q.time));
        speed->InsertNextValue(static_cast<float>(q.speed));
      }
      id->InsertNextValue(p.id);
      group->InsertNextValue(p.group);
      fate->InsertNextValue(static_cast<int>(r.fate));
      diameter->InsertNextValue(static_cast<float>(diameter_um(p.kind)));
    }
    auto poly = vtkSmartPointer<vtkPolyData>::New();
    poly->SetPoints(points);
    poly->SetLines(lines);
    poly->GetPointData()->AddArray(time);
    poly->GetPointData()->AddArray(speed);
    for (auto* a : {id.Get(), group.Get(), fate.Get()}) poly->GetCellData()->AddArray(a);
    poly->GetCellData()->AddArray(diameter);
    write_vtp(poly, out / "paths.vtp");
  }
  // deposits.vtp: where particles met a wall (their contact point, mm).
  {
    auto points = vtkSmartPointer<vtkPoints>::New();
    auto verts = vtkSmartPointer<vtkCellArray>::New();
    auto id = int_array("particle"), group = int_array("group"), patch = int_array("patch");
    auto diameter = float_array("diameter_um");
    for (std::size_t i = 0; i < d.particles.size(); ++i) {
      const ParticleResult& r = d.particles[i];
      if (r.fate != Fate::wall) continue;
      const Particle p = particle(static_cast<int>(i));
      const Vec3 x = r.contact / kMm;
      verts->InsertNextCell(1);
      verts->InsertCellPoint(points->InsertNextPoint(x[0], x[1], x[2]));
      id->InsertNextValue(p.id);
      group->InsertNextValue(p.group);
      patch->InsertNextValue(r.patch);
      diameter->InsertNextValue(static_cast<float>(diameter_um(p.kind)));
    }
    auto poly = vtkSmartPointer<vtkPolyData>::New();
    poly->SetPoints(points);
    poly->SetVerts(verts);
    for (auto* a : {id.Get(), group.Get(), patch.Get()}) poly->GetPointData()->AddArray(a);
    poly->GetPointData()->AddArray(diameter);
    write_vtp(poly, out / "deposits.vtp");
  }
  // particles.csv and crossings.csv.
  {
    CsvTable t({"particle", "group", "diameter_um", "density_kg_m3", "release_x_mm", "release_y_mm",
                "release_z_mm", "fate", "patch", "residence_time_s", "path_length_mm", "end_x_mm",
                "end_y_mm", "end_z_mm", "steps", "planes_crossed"});
    CsvTable c({"particle", "group", "diameter_um", "plane", "x_mm", "y_mm", "z_mm", "time_s"});
    for (std::size_t i = 0; i < d.particles.size(); ++i) {
      const ParticleResult& r = d.particles[i];
      const Particle p = particle(static_cast<int>(i));
      const ParticleKind& k = d.kinds[static_cast<std::size_t>(p.kind)];
      const std::string& g = d.release.groups[static_cast<std::size_t>(p.group)];
      const Vec3 x0 = d.release.points[static_cast<std::size_t>(p.point)] / kMm;
      const Vec3 end = (r.fate == Fate::wall ? r.contact : r.end) / kMm;
      t.add_row({std::to_string(p.id), g, number(k.diameter * 1e6),
                 k.tracer() ? "0" : number(k.density), number(x0[0]), number(x0[1]), number(x0[2]),
                 fate_name(r.fate), patch_name(r.patch), number(r.time), number(r.length / kMm),
                 number(end[0]), number(end[1]), number(end[2]), std::to_string(r.steps),
                 std::to_string(r.crossings.size())});
      for (const Crossing& x : r.crossings) {
        const Vec3 y = x.x / kMm;
        c.add_row({std::to_string(p.id), g, number(k.diameter * 1e6), std::to_string(x.plane + 1),
                   fmt::format("{:.15g}", y[0]), fmt::format("{:.15g}", y[1]),
                   fmt::format("{:.15g}", y[2]), fmt::format("{:.15g}", x.time)});
      }
    }
    t.write(out / "particles.csv");
    c.write(out / "crossings.csv");
  }
  // fates.csv: counts per group and species; deposition efficiency per wall patch.
  std::vector<int> wall_patches;
  for (std::size_t p = 0; p < d.mesh.patch_names.size(); ++p) {
    const std::string& n = d.mesh.patch_names[p];
    if (!is_open_patch(n)) wall_patches.push_back(static_cast<int>(p));
  }
  {
    std::vector<std::string> columns{"group", "diameter_um", "density_kg_m3", "released"};
    for (int f = 0; f < kFates; ++f) columns.push_back(fate_name(static_cast<Fate>(f)));
    for (int p : wall_patches) columns.push_back("deposited_" + patch_name(p));
    for (int p : wall_patches) columns.push_back("efficiency_" + patch_name(p));
    for (int p : d.result.region_patches) columns.push_back("through_" + patch_name(p));
    CsvTable t(columns);
    for (const TraceCounts& c : d.result.counts) {
      std::vector<std::string> row{c.group, number(c.diameter_um), number(c.density),
                                   std::to_string(c.released)};
      for (int f = 0; f < kFates; ++f) row.push_back(std::to_string(c.fates[f]));
      for (int p : wall_patches)
        row.push_back(std::to_string(c.deposited[static_cast<std::size_t>(p)]));
      for (int p : wall_patches)
        row.push_back(number(
            c.released ? c.deposited[static_cast<std::size_t>(p)] / double(c.released) : 0.0));
      for (int v : c.visited) row.push_back(std::to_string(v));
      t.add_row(std::move(row));
    }
    t.write(out / "fates.csv");
  }
  // summary.json.
  Json s;
  s["solution"] = d.job.solution.string();
  s["reynolds"] = significant(d.solution.reynolds);
  s["inlet_speed_m_s"] = significant(d.solution.u_in);
  s["release"] = d.job.release;
  s["release_points"] = d.release.points.size();
  s["groups"] = d.release.groups;
  Json species = Json::array();
  for (const ParticleKind& k : d.kinds)
    species.push_back(k.tracer() ? Json{{"tracer", true}}
                                 : Json{{"diameter_um", significant(k.diameter * 1e6)},
                                        {"density_kg_m3", significant(k.density)}});
  s["species"] = species;
  s["particles"] = d.result.particles;
  Json fates = Json::object();
  for (int f = 0; f < kFates; ++f) {
    int n = 0;
    for (const TraceCounts& c : d.result.counts) n += c.fates[f];
    fates[fate_name(static_cast<Fate>(f))] = n;
  }
  s["fates"] = fates;
  Json planes = Json::array();
  for (std::size_t i = 0; i < d.planes.size(); ++i)
    planes.push_back(
        {{"label", d.plane_labels[i]},
         {"point_mm",
          {significant(d.planes[i].point[0] / kMm), significant(d.planes[i].point[1] / kMm),
           significant(d.planes[i].point[2] / kMm)}},
         {"normal",
          {significant(d.planes[i].normal[0]), significant(d.planes[i].normal[1]),
           significant(d.planes[i].normal[2])}}});
  s["planes"] = planes;
  Json groups = Json::array();
  for (const TraceCounts& c : d.result.counts) {
    Json g{
        {"group", c.group}, {"diameter_um", significant(c.diameter_um)}, {"released", c.released}};
    for (int f = 0; f < kFates; ++f) g[fate_name(static_cast<Fate>(f))] = c.fates[f];
    Json through = Json::object();
    for (std::size_t i = 0; i < c.visited.size(); ++i)
      through[patch_name(d.result.region_patches[i])] = c.visited[i];
    g["through_regions"] = through;
    groups.push_back(g);
  }
  s["per_group"] = groups;
  s["gravity_m_s2"] = d.job.gravity;
  s["drag"] = d.job.drag;
  s["steps"] = d.result.steps;
  s["cell_tests_per_step"] =
      significant(static_cast<double>(d.result.cell_tests) / std::max(d.result.steps, 1L));
  s["steps_per_second"] = significant(d.result.steps / std::max(d.result.track_seconds, 1e-9));
  s["track_seconds"] = significant(d.result.track_seconds);
  s["seconds"] = significant(d.result.seconds);
  s["mpi_ranks"] = d.result.ranks;
  write_json_file(out / "summary.json", s);
}

}  // namespace naris::particles
