#include "app/trace_figures.h"

#include <fmt/format.h>

#include "core/units.h"
#include "postproc/figures/particle_figures.h"

namespace naris::app {
namespace {

using particles::Vec3;

figures::Point3 point3(const Vec3& x) {
  return {x[0], x[1], x[2]};
}

}  // namespace

void write_trace_figures(const particles::TraceResult& r, const std::filesystem::path& out) {
  // The view: the first plane's normal (with planes by distance, the inlet → outlet axis) to the
  // right, "up" (+z) made orthogonal to it.
  const Vec3 right = r.planes.empty() ? Vec3::UnitY() : r.planes.front().normal;
  Vec3 up = Vec3::UnitZ() - Vec3::UnitZ().dot(right) * right;
  if (up.norm() < 1e-6) up = Vec3::UnitX();
  up.normalize();

  figures::PathFigure f;
  f.title = fmt::format("Particle paths: {} particles from {} release group(s)", r.particles,
                        r.groups.size());
  f.caption = "Colour: release group. The airway wall is drawn translucent.";
  f.groups = r.groups;
  f.right = point3(right);
  f.up = point3(up);
  f.right_label =
      fmt::format("({:.2f}, {:.2f}, {:.2f}), inlet → outlet", right[0], right[1], right[2]);
  f.up_label = fmt::format("({:.2f}, {:.2f}, {:.2f})", up[0], up[1], up[2]);
  for (const auto& t : r.wall) f.surface.push_back({point3(t[0]), point3(t[1]), point3(t[2])});
  for (std::size_t i = 0; i < r.tracks.size(); ++i) {
    if (r.tracks[i].path.size() < 2) continue;
    std::vector<figures::Point3> p;
    for (const auto& q : r.tracks[i].path) p.push_back(point3(q.x / kMm));
    f.paths.push_back(std::move(p));
    f.path_group.push_back(r.track_group[i]);
  }
  figures::write_path_figure(f, out / "paths.png");
  if (r.planes.empty()) return;

  // Crossings, in each plane's coordinates: v = up within the plane, u = v × n.
  figures::CrossingFigure c;
  c.title = "Where the particles cross the planes";
  c.caption = "Colour: release group; black: the airway's outline on the plane.";
  c.groups = r.groups;
  c.u_label = "u = v × n";
  c.v_label = "v = up in the plane";
  for (std::size_t k = 0; k < r.planes.size(); ++k) {
    const Vec3 n = r.planes[k].normal, o = r.planes[k].point / kMm;
    Vec3 v = Vec3::UnitZ() - Vec3::UnitZ().dot(n) * n;
    if (v.norm() < 1e-6) v = Vec3::UnitX() - Vec3::UnitX().dot(n) * n;
    v.normalize();
    const Vec3 u = v.cross(n);
    auto in_plane = [&](const Vec3& x) { return figures::Point2{(x - o).dot(u), (x - o).dot(v)}; };
    figures::SectionPanel p;
    p.title = fmt::format("plane {}: {}", k + 1, r.plane_labels[k]);
    for (const auto& t : r.wall) {
      double s[3];
      for (int i = 0; i < 3; ++i) s[i] = n.dot(t[static_cast<std::size_t>(i)] - o);
      Vec3 ends[2];
      int found = 0;
      for (int i = 0; i < 3 && found < 2; ++i) {
        const int j = (i + 1) % 3;
        if ((s[i] < 0.0) == (s[j] < 0.0)) continue;
        const double w = s[i] / (s[i] - s[j]);
        ends[found++] = t[static_cast<std::size_t>(i)] +
                        w * (t[static_cast<std::size_t>(j)] - t[static_cast<std::size_t>(i)]);
      }
      if (found == 2) p.outline.push_back({in_plane(ends[0]), in_plane(ends[1])});
    }
    for (std::size_t i = 0; i < r.tracks.size(); ++i)
      for (const auto& x : r.tracks[i].crossings)
        if (x.plane == static_cast<int>(k)) {
          p.points.push_back(in_plane(x.x / kMm));
          p.point_group.push_back(r.track_group[i]);
        }
    c.panels.push_back(std::move(p));
  }
  figures::write_crossing_figure(c, out / "crossings.png");
}

}  // namespace naris::app
