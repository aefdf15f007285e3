#include "postproc/planes/drawing.h"

#include <fmt/format.h>
#include <vtkBandedPolyDataContourFilter.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkProbeFilter.h>
#include <vtkStripper.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/units.h"

namespace naris::planes {
namespace {

namespace fs = std::filesystem;
using Vec3 = Eigen::Vector3d;

// The figure's frame: v is "up" (+z, the patient's superior) within the plane, u = n × v, so
// the plane is seen from the anterior (looking along the inlet → outlet axis).
struct Frame {
  Vec3 origin, u, v;
  figures::Point2 operator()(const Vec3& x) const {
    return {(x - origin).dot(u), (x - origin).dot(v)};
  }
};

Frame frame_of(const SectionPlane& p) {
  Vec3 v = Vec3::UnitZ() - Vec3::UnitZ().dot(p.normal) * p.normal;
  if (v.norm() < 1e-6) v = Vec3::UnitY() - Vec3::UnitY().dot(p.normal) * p.normal;
  v.normalize();
  return {p.point, p.normal.cross(v), v};
}

}  // namespace

std::vector<Crossing> read_crossings(const fs::path& path, std::vector<std::string>& groups) {
  std::ifstream in(path);
  if (!in) fail("{}: cannot read the crossings (run naris trace first)", path.string());
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  auto split = [](const std::string& s) {
    std::vector<std::string> f;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    return f;
  };
  header = split(line);
  auto column = [&](const char* name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end())
      fail("{}: no column '{}' (not a crossings.csv of naris trace)", path.string(), name);
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t g = column("group"), x = column("x_mm"), y = column("y_mm"), z = column("z_mm");
  std::map<std::string, int> id;
  std::vector<Crossing> out;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto f = split(line);
    if (f.size() < header.size()) fail("{}: a short row: '{}'", path.string(), line);
    auto [it, added] = id.try_emplace(f[g], static_cast<int>(groups.size()));
    if (added) groups.push_back(f[g]);
    try {
      out.push_back({Vec3(std::stod(f[x]), std::stod(f[y]), std::stod(f[z])), it->second});
    } catch (const std::exception&) {
      fail("{}: '{}' is not a row of numbers", path.string(), line);
    }
  }
  return out;
}

namespace {

std::vector<figures::Polyline2> polylines(vtkPolyData* lines, const Frame& frame) {
  std::vector<figures::Polyline2> out;
  vtkNew<vtkIdList> ids;
  vtkCellArray* cells = lines->GetLines();
  cells->InitTraversal();
  while (cells->GetNextCell(ids)) {
    figures::Polyline2 p;
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) {
      double x[3];
      lines->GetPoint(ids->GetId(k), x);
      p.push_back(frame(Vec3(x[0], x[1], x[2])));
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

figures::SectionFigure section_figure(const Section& s, const DrawingOptions& o,
                                      const std::vector<Crossing>& crossings,
                                      const std::vector<std::string>& groups) {
  const double u_in = o.u_in;
  const Frame frame = frame_of(s.plane);
  figures::SectionFigure f;
  f.levels = o.levels;
  f.max_speed = o.max_speed > 0.0 ? o.max_speed : s.whole.max_speed;
  f.u_in = u_in;
  for (const Loop& loop : s.outline) {
    figures::Polyline2 p;
    for (const Vec3& x : loop) p.push_back(frame(x));
    f.outline.push_back(std::move(p));
  }
  // Bands and their edges by VTK's banded contour filter, on the speed.
  vtkNew<vtkBandedPolyDataContourFilter> bands;
  bands->SetInputData(s.surface);
  bands->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "speed");
  bands->GenerateValues(o.levels + 1, 0.0, std::max(f.max_speed, 1e-300));
  bands->SetScalarModeToIndex();
  bands->GenerateContourEdgesOn();
  bands->Update();
  vtkPolyData* filled = bands->GetOutput();
  vtkDataArray* index = filled->GetCellData()->GetScalars();
  vtkNew<vtkIdList> ids;
  vtkCellArray* polys = filled->GetPolys();
  polys->InitTraversal();
  for (vtkIdType c = 0; polys->GetNextCell(ids); ++c) {
    figures::Polyline2 p;
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) {
      double x[3];
      filled->GetPoint(ids->GetId(k), x);
      p.push_back(frame(Vec3(x[0], x[1], x[2])));
    }
    f.bands.push_back(std::move(p));
    const int band = index ? static_cast<int>(index->GetTuple1(filled->GetNumberOfVerts() +
                                                               filled->GetNumberOfLines() + c))
                           : 0;
    f.band.push_back(std::clamp(band, 0, o.levels - 1));
  }
  vtkNew<vtkStripper> edges;
  edges->SetInputConnection(bands->GetOutputPort(1));
  edges->Update();
  f.contours = polylines(edges->GetOutput(), frame);

  // The secondary velocity on a regular grid in the plane, probed on the section.
  double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
  for (const auto& loop : f.outline)
    for (const auto& p : loop)
      u0 = std::min(u0, p[0]), u1 = std::max(u1, p[0]), v0 = std::min(v0, p[1]),
      v1 = std::max(v1, p[1]);
  f.arrow_spacing = std::max(u1 - u0, v1 - v0) / o.arrows_across;
  vtkNew<vtkPoints> grid;
  grid->SetDataTypeToDouble();
  for (double b = v0 + 0.5 * f.arrow_spacing; b < v1; b += f.arrow_spacing)
    for (double a = u0 + 0.5 * f.arrow_spacing; a < u1; a += f.arrow_spacing)
      grid->InsertNextPoint(Vec3(frame.origin + a * frame.u + b * frame.v).data());
  vtkNew<vtkPolyData> at;
  at->SetPoints(grid);
  vtkNew<vtkProbeFilter> probe;
  probe->SetInputData(at);
  probe->SetSourceData(s.surface);
  probe->Update();
  vtkDataSet* sampled = probe->GetOutput();
  vtkDataArray* secondary = sampled->GetPointData()->GetArray("secondary_velocity");
  vtkDataArray* valid = sampled->GetPointData()->GetArray(probe->GetValidPointMaskArrayName());
  for (vtkIdType i = 0; secondary && valid && i < sampled->GetNumberOfPoints(); ++i) {
    if (valid->GetTuple1(i) == 0.0) continue;
    double x[3], w[3];
    sampled->GetPoint(i, x);
    secondary->GetTuple(i, w);
    const Vec3 sv(w[0], w[1], w[2]);
    f.arrows.push_back({frame(Vec3(x[0], x[1], x[2])), {sv.dot(frame.u), sv.dot(frame.v)}});
  }

  const double scale = std::max(1.0, s.plane.point.cwiseAbs().maxCoeff());
  for (const Crossing& c : crossings)
    if (std::abs(s.plane.normal.dot(c.x - s.plane.point)) < 1e-6 * scale) {
      f.crossings.push_back(frame(c.x));
      f.crossing_group.push_back(c.group);
    }
  if (!f.crossings.empty()) f.groups = groups;

  const Vec3& n = s.plane.normal;
  f.title = s.plane.by_distance
                ? fmt::format("Cross-section {:g} mm from the anterior tip", s.plane.distance)
                : fmt::format("Cross-section on the plane {}", s.plane.label);
  f.u_label = fmt::format("u (mm), u = n × up, n = ({:.2f}, {:.2f}, {:.2f})", n[0], n[1], n[2]);
  f.v_label = "v (mm), up in the plane";
  f.caption = fmt::format(
      "Speed: {} bands and contours in equal steps from 0 at the wall to the maximum,\n"
      "{:.3g} m/s ({:.3g} U_in); maximum axial velocity {:.3g} m/s ({:.3g} U_in).\n"
      "Arrows: the secondary (in-plane) velocity. Seen from the anterior.\n"
      "Area {:.4g} mm², perimeter {:.4g} mm (smoothed), flux {:.4g} mL/s.",
      o.levels, s.whole.max_speed, s.whole.max_speed / u_in, s.whole.max_axial,
      s.whole.max_axial / u_in, s.whole.area, s.whole.perimeter, s.whole.flux * kMlPerM3);
  if (!f.crossings.empty())
    f.caption += fmt::format("\nCircles: {} particle crossings, coloured by release group.",
                             f.crossings.size());
  return f;
}

}  // namespace naris::planes
