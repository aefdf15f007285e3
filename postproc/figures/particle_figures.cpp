#include "postproc/figures/particle_figures.h"

#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>

#include "core/error.h"
#include "postproc/figures/canvas.h"

namespace naris::figures {
namespace {

double dot(const Point3& a, const Point3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Point3 sub(const Point3& a, const Point3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

}  // namespace

void write_path_figure(const PathFigure& f, const std::filesystem::path& path, int width,
                       int height) {
  if (f.surface.empty()) fail("{}: no airway surface to draw", path.string());
  const Point3 depth = cross(f.right, f.up);  // towards the viewer
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& t : f.surface)
    for (const Point3& p : t) {
      x0 = std::min(x0, dot(p, f.right)), x1 = std::max(x1, dot(p, f.right));
      y0 = std::min(y0, dot(p, f.up)), y1 = std::max(y1, dot(p, f.up));
    }
  const double left = 70, right = width - 230, top = 60, bottom = height - 80;
  const double scale = std::min((right - left) / (x1 - x0), (bottom - top) / (y1 - y0));
  const double ox = left + 0.5 * ((right - left) - scale * (x1 - x0));
  const double oy = bottom - 0.5 * ((bottom - top) - scale * (y1 - y0));
  auto px = [&](const Point3& p) { return ox + (dot(p, f.right) - x0) * scale; };
  auto py = [&](const Point3& p) { return oy - (dot(p, f.up) - y0) * scale; };

  const Canvas canvas(width, height);
  cairo_t* cr = canvas.cr();

  // The wall, far to near, each triangle a translucent grey shaded by how squarely it faces
  // the viewer: overlapping layers darken, so the airway reads as a volume.
  std::vector<std::size_t> order(f.surface.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<double> z(f.surface.size());
  for (std::size_t i = 0; i < f.surface.size(); ++i)
    z[i] = dot(f.surface[i][0], depth) + dot(f.surface[i][1], depth) + dot(f.surface[i][2], depth);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return z[a] < z[b]; });
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
  for (std::size_t i : order) {
    const auto& t = f.surface[i];
    const Point3 n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    const double len = std::sqrt(dot(n, n));
    if (len == 0.0) continue;
    const double facing = std::abs(dot(n, depth)) / len;
    const double shade = 0.25 + 0.5 * facing;
    cairo_set_source_rgba(cr, shade, shade, shade * 1.02, 0.15);
    cairo_move_to(cr, px(t[0]), py(t[0]));
    cairo_line_to(cr, px(t[1]), py(t[1]));
    cairo_line_to(cr, px(t[2]), py(t[2]));
    cairo_close_path(cr);
    cairo_fill(cr);
  }
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);
  cairo_set_line_width(cr, 1.1);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (std::size_t i = 0; i < f.paths.size(); ++i) {
    const auto& p = f.paths[i];
    if (p.size() < 2) continue;
    const auto c = group_colour(f.path_group[i]);
    cairo_set_source_rgba(cr, c[0], c[1], c[2], 0.75);
    cairo_move_to(cr, px(p[0]), py(p[0]));
    for (std::size_t k = 1; k < p.size(); ++k) cairo_line_to(cr, px(p[k]), py(p[k]));
    cairo_stroke(cr);
  }
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  canvas.text(0.5 * width, 22, f.title, 20, 0.5, 0.0);
  canvas.text(left, height - 40, f.caption, 14, 0.0, 0.5);
  canvas.text(left, height - 18, "screen right: " + f.right_label + ", up: " + f.up_label, 13, 0.0,
              0.5);
  group_legend(canvas, f.groups, right + 30, top + 20);
  scale_bar(canvas, right + 30, bottom - 20, scale, x1 - x0);
  canvas.write_png(path);
}

void write_crossing_figure(const CrossingFigure& f, const std::filesystem::path& path,
                           int panel_size) {
  if (f.panels.empty()) fail("{}: no planes to draw", path.string());
  const int n = static_cast<int>(f.panels.size());
  const int columns = n <= 3 ? n : (n + 1) / 2, rows = (n + columns - 1) / columns;
  // One scale for every panel: the largest section's extent.
  double span = 0.0;
  std::vector<std::array<double, 4>> bounds;
  for (const SectionPanel& p : f.panels) {
    double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (const auto& s : p.outline)
      for (const Point2& q : s)
        u0 = std::min(u0, q[0]), u1 = std::max(u1, q[0]), v0 = std::min(v0, q[1]),
        v1 = std::max(v1, q[1]);
    for (const Point2& q : p.points)
      u0 = std::min(u0, q[0]), u1 = std::max(u1, q[0]), v0 = std::min(v0, q[1]),
      v1 = std::max(v1, q[1]);
    if (!(u1 > u0)) u0 = v0 = -1.0, u1 = v1 = 1.0;
    span = std::max({span, u1 - u0, v1 - v0});
    bounds.push_back({u0, u1, v0, v1});
  }
  const int header = 50, footer = 70, legend_width = 200;
  const int width = columns * panel_size + legend_width,
            height = rows * panel_size + header + footer;
  const Canvas canvas(width, height);
  cairo_t* cr = canvas.cr();
  const double margin = 36, scale = (panel_size - 2 * margin) / span;
  for (int i = 0; i < n; ++i) {
    const SectionPanel& p = f.panels[static_cast<std::size_t>(i)];
    const double cx = (i % columns) * panel_size + 0.5 * panel_size;
    const double cy = header + (i / columns) * panel_size + 0.5 * panel_size + 10;
    const double mu =
        0.5 * (bounds[static_cast<std::size_t>(i)][0] + bounds[static_cast<std::size_t>(i)][1]);
    const double mv =
        0.5 * (bounds[static_cast<std::size_t>(i)][2] + bounds[static_cast<std::size_t>(i)][3]);
    auto px = [&](const Point2& q) { return cx + (q[0] - mu) * scale; };
    auto py = [&](const Point2& q) { return cy - (q[1] - mv) * scale; };
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    canvas.text(cx, cy - 0.5 * panel_size + 8, p.title, 15, 0.5, 0.0);
    cairo_set_line_width(cr, 1.2);
    for (const auto& s : p.outline) {
      cairo_move_to(cr, px(s[0]), py(s[0]));
      cairo_line_to(cr, px(s[1]), py(s[1]));
    }
    cairo_stroke(cr);
    for (std::size_t k = 0; k < p.points.size(); ++k) {
      const auto c = group_colour(p.point_group[k]);
      cairo_set_source_rgba(cr, c[0], c[1], c[2], 0.85);
      cairo_arc(cr, px(p.points[k]), py(p.points[k]), 2.6, 0, 2 * M_PI);
      cairo_fill(cr);
    }
  }
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  canvas.text(0.5 * (width - legend_width), 14, f.title, 20, 0.5, 0.0);
  canvas.text(20, height - 40, f.caption, 14, 0.0, 0.5);
  canvas.text(20, height - 18, f.u_label + " → right, " + f.v_label + " ↑", 13, 0.0, 0.5);
  group_legend(canvas, f.groups, columns * panel_size + 20, header + 30);
  scale_bar(canvas, columns * panel_size + 20, height - footer - 20, scale, span);
  canvas.write_png(path);
}

}  // namespace naris::figures
